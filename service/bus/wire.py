"""What the zenoh bus puts on the wire and how it quotes remote text: contract JSON, a sample's
payload, a short one-line error, a spectrum's JSON, the accelerometer blocks queued beside the
snapshots. Shared by the channel's outbox (service.bus.twin_outbox), its inbox
(service.bus.twin_inbox) and the bus (service.bus.zenoh_bus)."""

from __future__ import annotations

import json
from typing import Any, Protocol

import zenoh

JSON_ENCODING = "application/json"


class Bus(Protocol):
    """What a channel's parts use of the bus (service.bus.zenoh_bus.ZenohBus)."""

    session: zenoh.Session
    prefix: str

    def owner(self, bearing_id: str) -> dict:
        """Who runs the twin (the owner query's answer)."""


class Waveform:
    """Accelerometer blocks queued with the snapshots (publisher thread)."""

    __slots__ = ("blocks",)

    def __init__(self, blocks: list):
        self.blocks = blocks


def quoted(value: Any, limit: int = 80) -> str:
    """Remote text for a log line: at most `limit` characters, quoted with control characters
    escaped (repr), so a peer cannot forge or split log lines."""
    return repr(str(value)[:limit])


def one_line(exc: BaseException) -> str:
    """A short, single-line description of a refusal (pydantic errors name their field)."""
    errors = getattr(exc, "errors", None)
    if callable(errors) and type(exc).__name__ == "ValidationError":
        try:
            parts = []
            for e in errors():
                loc = ".".join(str(p) for p in e.get("loc", ())) or "payload"
                parts.append(f"{loc}: {e.get('msg', '')}")
            if parts:
                return "; ".join(parts)
        except Exception:  # noqa: BLE001 - fall back to str()
            pass
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


def dumps(obj: Any) -> str:
    """Contract JSON: compact, never NaN/Infinity (raises ValueError instead)."""
    return json.dumps(obj, allow_nan=False, separators=(",", ":"))


def spectrum_json(spectrum: Any) -> dict | None:
    """A window's spectrum (twin.snapshot.Spectrum) for `P/{id}/vibration`: its axis and the
    amplitudes rounded to 6 significant digits (half the text of full doubles); None without one."""
    if spectrum is None:
        return None
    amp = spectrum.amplitude_m_s2
    return {
        "start_hz": spectrum.start_hz,
        "step_hz": spectrum.step_hz,
        "bins": len(amp),
        "units": "m/s^2",
        "amplitude_m_s2": [float(f"{a:.6g}") for a in amp],
    }


def payload(sample: zenoh.Sample) -> bytes:
    """A sample's payload bytes; b"" when they cannot be read (the intake refuses those)."""
    try:
        return sample.payload.to_bytes()
    except Exception:  # noqa: BLE001
        return b""
