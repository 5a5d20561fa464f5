"""The transport-free robot: the command executor and the memory it keeps.

Nothing here imports MQTT, AWS or ROS. The executor takes decoded commands and backend
callbacks and emits events and reported states through callables it is given, so many
robots can run in one process (swarm mode) and tests can run faster than real time. Its
time is injected (`robot_agent.clock`, shared with the simulator backend); it reaches the
robot's adapters only through their ports (`robot_agent.backends.port`,
`robot_agent.voice.port`), which import nothing of the core.
"""
