"""One module per resource: health, bearings, setpoint, state, alarms, scenarios, recording, docs."""
