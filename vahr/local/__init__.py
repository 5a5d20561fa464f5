"""The whole system on one machine: broker supervisor, shadow service, data-plane API,
Alexa simulator. The same topics and shadow semantics as AWS IoT Core."""
