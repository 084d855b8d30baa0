"""Operator tools on top of the service: the CLI commands, monitor, soak, the service benchmark,
offline scenario runs and the EHL commands."""
