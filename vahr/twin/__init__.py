"""The twin of AWS IoT on one machine: the broker supervisor and its ACL, the device
shadow service and store, the iot-data HTTP API, the fleet index, and `LocalStack`
starting them in order."""
