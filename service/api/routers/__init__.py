"""One module per resource: health, bearings, setpoint, state, scenarios, recording, docs."""
