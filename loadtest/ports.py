"""Free TCP ports on the loopback for the services the load tools start."""

from __future__ import annotations

import contextlib
import socket


def free_ports(count: int) -> list[int]:
    """`count` distinct free ports on 127.0.0.1: all sockets are bound at once before any is
    closed, so the kernel cannot hand the same ephemeral port out twice (one port asked for at a
    time can come back for the next ask, and the service's HTTP and zenoh then collide)."""
    with contextlib.ExitStack() as stack:
        sockets = [stack.enter_context(socket.socket(socket.AF_INET, socket.SOCK_STREAM)) for _ in range(count)]
        for s in sockets:
            s.bind(("127.0.0.1", 0))
        return [s.getsockname()[1] for s in sockets]
