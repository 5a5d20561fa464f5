"""The paper's experiment: tasks I-III, the event log, the judge, HRI metrics and the report.

Modules, in the order data flows through them:

- `tasks`: the three tasks and the seeded plan of one session (zone assignments, weather).
- `eventlog`: the append-only, crash-safe SQLite log of one session.
- `world`: the floor's arms, packages and the task III success LED, driven by robot events.
- `judge`: scores each task from the log exactly as the paper defines success.
- `measure`: interaction effort, neglect time and task time from the log.
- `metrics`: the HRI formulas (RAD, fan-out, trust-adjusted RAD).
- `tlx`: NASA-TLX levels and their conversion to percent.
- `results`: the one-row-per-session table (the report's CSV).
- `report` and `figures`: the paper's tables, ANOVA p-values and charts.
- `timing`, `participant`, `session`: the simulated participant and the session runner.
"""
