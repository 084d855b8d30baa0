"""bearing-twin service: HTTP (api), zenoh (bus), rerun (recorder), the core it wraps, tools and reports."""
