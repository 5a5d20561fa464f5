"""The lab side's plumbing: the paho MQTT client, HTTP serving, loopback ports, child
processes, and the `Assistant` port with its clients."""
