"""bearing-twin's engine: a real-time DEM twin of a lubricated ball bearing.

The public face (imported lazily, so `import twin.setpoint` stays light)::

    from twin import Twin, catalog, Setpoint, SetpointUpdate, SetpointLimits, Snapshot
    twin = Twin("6208")                          # warm-started at 500 rad/s, 3000 N, 40 degC
    twin.set_setpoint(radial_load_n=5000.0)      # partial, checked against the bearing's limits
    twin.advance(0.01)                           # 10 ms of simulated time
    snap: Snapshot = twin.snapshot()             # schema "bearing-twin/state/1"

Runtime engine: spec.py -> model.py (immutable arrays) + state.py -> kernels/step.py, driven by
engine.py; physics/ holds one law per function. Offline science (analytic references, studies,
calibrations, benchmarks) is in twin.validation; the seed-003 EHL reference solver in
twin.ehl_solver. `twin` never imports the service layer.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__all__ = [
    "BearingSpec",
    "Fault",
    "Setpoint",
    "SetpointError",
    "SetpointLimits",
    "SetpointUpdate",
    "Snapshot",
    "Twin",
    "catalog",
]

_WHERE = {
    "Twin": "twin.engine",
    "Setpoint": "twin.setpoint",
    "SetpointUpdate": "twin.setpoint",
    "SetpointLimits": "twin.setpoint",
    "SetpointError": "twin.setpoint",
    "Snapshot": "twin.snapshot",
    "BearingSpec": "twin.spec",
    "Fault": "twin.faults",
}

if TYPE_CHECKING:
    from twin import catalog
    from twin.engine import Twin
    from twin.faults import Fault
    from twin.setpoint import Setpoint, SetpointError, SetpointLimits, SetpointUpdate
    from twin.snapshot import Snapshot
    from twin.spec import BearingSpec


def __getattr__(name: str) -> Any:
    if name == "catalog":
        return importlib.import_module("twin.catalog")
    if name in _WHERE:
        return getattr(importlib.import_module(_WHERE[name]), name)
    raise AttributeError(f"module 'twin' has no attribute {name!r}")
