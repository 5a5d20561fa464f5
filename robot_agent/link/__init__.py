"""The robot's link to the broker: the `Link` port, the awsiotsdk MQTT 5 adapter, and the
classic device shadow spoken over it."""
