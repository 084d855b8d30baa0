"""The one place that sets numba compilation flags for every kernel (PySDM-style hygiene).

- `nogil=True`: the service's HTTP threads keep running while a frame integrates.
- `cache=True`: compiled kernels are cached on disk, start-up stays short.
- no `fastmath`: it would let LLVM assume no NaN and drop the kernel's divergence check.
- the default error model: `error_model="numpy"` and `inline="always"` were both measured here
  to make the contact kernels 20-25x slower (14 ns -> 360 ns for nine ball-cage checks), so
  every division in a kernel is guarded instead, and kernels report a status, never raise.
"""

JIT = dict(nogil=True, cache=True)

# Branch-free array loops (contact geometry) use numpy's error model so that divisions carry no
# zero check and LLVM can vectorise them; their inputs never divide by zero (the ball centre is
# never on the bearing axis nor on the groove-centre circle).
JIT_VECTOR = dict(JIT, error_model="numpy")

# Branch-free array loops (contact geometry) use numpy's error model so that divisions carry no
# zero check and LLVM can vectorise them; their inputs never divide by zero (the ball centre is
# never on the bearing axis nor on the groove-centre circle).
JIT_VECTOR = dict(JIT, error_model="numpy")
