"""Free TCP ports on the loopback for the services the load tools and the tests start."""

from __future__ import annotations

import contextlib
import socket
import threading

_handed_out: set[int] = set()  # ports this process has been given by free_port / free_ports
_lock = threading.Lock()


def free_ports(count: int) -> list[int]:
    """`count` distinct free ports on 127.0.0.1 that this process has not been given before.

    All sockets are bound at once before any is closed, so the kernel cannot hand the same
    ephemeral port out twice within one ask; a port released by an earlier ask can come back
    for the next one, so those are asked for again (a service's HTTP and zenoh ports, or two
    services of one test, would otherwise collide)."""
    if count < 1:
        raise ValueError("count must be >= 1")
    with _lock:
        for _ in range(100):
            with contextlib.ExitStack() as stack:
                sockets = [stack.enter_context(socket.socket(socket.AF_INET, socket.SOCK_STREAM)) for _ in range(count)]
                for s in sockets:
                    s.bind(("127.0.0.1", 0))
                ports = [s.getsockname()[1] for s in sockets]
            if not _handed_out.intersection(ports):
                _handed_out.update(ports)
                return ports
    raise RuntimeError(f"no {count} loopback ports that this process has not been given already")


def free_port() -> int:
    """One free port on 127.0.0.1 that this process has not been given before (`free_ports`)."""
    return free_ports(1)[0]
