"""Live: drive vehicles over VDA 5050 on an MQTT broker."""
