"""The zenoh bus: session, per-twin channels and key expressions (`service.bus.zenoh_bus`)."""
