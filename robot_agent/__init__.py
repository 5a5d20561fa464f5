"""robot-agent: the program each robot runs.

`core` is the pure command executor, `link` the MQTT and shadow adapter (awsiotsdk),
`backends/` the navigation backends (sim, ros1) and `voice/` the robot's speech.
"""
