"""VAHR: Virtual Assistant, Human, and Robots in the loop.

`vahr.protocol` is the wire contract shared by every part; `vahr.local` runs the whole
system on one machine; `vahr.experiment` runs and scores the paper's experiment.
"""
