"""The service's core: twin registry, runner frame loop (pacing, mailbox, fault policy, scenarios,
publishing, statistics), the one admission gate and the setpoint intake. No fastapi, no zenoh,
no rerun (import-linter contract "core" in pyproject.toml)."""
