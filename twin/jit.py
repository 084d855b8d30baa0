"""The one place that sets numba compilation flags for every kernel (PySDM-style hygiene).

- `nogil=True`: the service's HTTP threads keep running while a frame integrates.
- `cache=True`: compiled kernels are cached on disk, start-up stays short.
- no `fastmath`: it would let LLVM assume no NaN and drop the kernel's divergence check.
- the default error model, except for branch-free lane loops (`JIT_VECTOR`): `error_model=
  "numpy"` elsewhere and `inline="always"` were measured to make scalar contact kernels 20-25x
  slower here, so every division in a kernel is guarded, and kernels report a status, never raise.

Cache safety: numba keys its on-disk cache on each function's own source file, not on the
module-level constants it imports (the lane layout, for instance), so a stale kernel could
survive a layout change. The cache therefore lives in a directory named after a hash of every
source file of `twin/`: any change to the engine compiles afresh.
"""

import hashlib
import os
from pathlib import Path

import numba


def _engine_cache_dir() -> str:
    root = Path(__file__).resolve().parent
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    base = os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
        "bearing-twin")
    return os.path.join(base, f"numba-{digest.hexdigest()[:16]}")


numba.config.CACHE_DIR = _engine_cache_dir()

JIT = dict(nogil=True, cache=True)

# Branch-free array loops (contact lanes) use numpy's error model so that divisions carry no
# zero check and LLVM can vectorise them; their inputs never divide by zero (the ball centre is
# never on the bearing axis nor on the groove-centre circle).
JIT_VECTOR = dict(JIT, error_model="numpy")

# The step (`twin.kernels.step.step_n`): numpy's error model too, so that the lane passes inlined
# into it (numba-level `inline="always"`: no array crosses a call inside the loop, hence no
# reference counting per pass) keep their vectorised form, and without numba's reference-counted
# runtime (`_nrt=False`: the step allocates nothing, and the arrays it is given outlive the call;
# with it, every inlined pass counted its array arguments up and down with atomic operations,
# ~6 % of the step); a division by zero gives inf / NaN,
# which the step's finiteness check reports as a status (python's model would raise instead).
JIT_STEP = dict(JIT_VECTOR, _nrt=False)
