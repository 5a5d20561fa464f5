"""The transport-free robot: the command executor, its clock, and the memory it keeps.

Nothing here imports MQTT, AWS or ROS. The executor takes decoded commands and backend
callbacks and emits events and reported states through callables it is given, so many
robots can run in one process (swarm mode) and tests can run faster than real time.
"""
