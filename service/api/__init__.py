"""The HTTP API: `create_app` (app.py), one router per resource (routers/), dependencies (deps.py),
schemas, error handlers and the body size cap."""
