"""The nodes of one twin in the OPC UA server (`TwinNodes`) and the OPC UA types the server writes
and accepts: variant types by name, the numeric types a setpoint write may carry, the alarm event fields.
"""

from __future__ import annotations

from typing import Any

from asyncua import ua
from asyncua.server.event_generator import EventGenerator

VARIANT_TYPES = {
    "Double": ua.VariantType.Double,
    "String": ua.VariantType.String,
    "UInt32": ua.VariantType.UInt32,
    "Int64": ua.VariantType.Int64,
    "Boolean": ua.VariantType.Boolean,
}
NUMERIC_TYPES = {
    ua.VariantType.Double,
    ua.VariantType.Float,
    ua.VariantType.SByte,
    ua.VariantType.Byte,
    ua.VariantType.Int16,
    ua.VariantType.UInt16,
    ua.VariantType.Int32,
    ua.VariantType.UInt32,
    ua.VariantType.Int64,
    ua.VariantType.UInt64,
}
EVENT_FIELDS = (
    ("alarm_id", ua.VariantType.String),
    ("category", ua.VariantType.String),
    ("transition", ua.VariantType.String),
    ("active", ua.VariantType.Boolean),
    ("level", ua.VariantType.String),
    ("value", ua.VariantType.Double),
    ("threshold", ua.VariantType.Double),
    ("clear_threshold", ua.VariantType.Double),
    ("unit", ua.VariantType.String),
    ("since_s", ua.VariantType.Double),
    ("time_s", ua.VariantType.Double),
)


def node_id(identifier: int | str, namespace: int = 0) -> ua.NodeId:
    """asyncua annotates NodeId's fields with its own int / str subclasses; it takes the built-ins."""
    return ua.NodeId(identifier, namespace)  # type: ignore[arg-type]


def status_code(name: str) -> ua.StatusCode:
    return ua.StatusCode(getattr(ua.StatusCodes, name))


class TwinNodes:
    """The nodes of one twin in the server."""

    def __init__(self, bearing_id: str, obj: Any):
        self.bearing_id = bearing_id
        self.obj = obj
        self.vars: dict[str, tuple[ua.NodeId, ua.VariantType, Any]] = {}  # key -> (node id, type, reader)
        self.last: dict[str, Any] = {}
        self.seq: int | None = None
        self.generators: list[EventGenerator] = []
        self.last_results: dict[str, ua.NodeId] = {}  # input folder -> its last_result variable
