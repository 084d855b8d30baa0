"""Load tools of bearing-twin (`bearing-twin-loadtest`): soak, attack and bench-service drive a
running service over HTTP and zenoh. Not part of the runtime: their HTTP client (httpx) comes with
the `loadtest` extra (`pip install -c constraints.txt '.[loadtest]'`)."""
