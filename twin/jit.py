"""The one place that sets numba compilation flags for every kernel (PySDM-style hygiene).

- `nogil=True`: the service's HTTP threads keep running while a frame integrates.
- `cache=True`: compiled kernels are cached on disk, start-up stays short.
- no `fastmath`: it would let LLVM assume no NaN and drop the kernel's divergence check.
- the default error model, except for branch-free lane loops (`JIT_VECTOR`): `error_model=
  "numpy"` elsewhere and `inline="always"` were measured to make scalar contact kernels 20-25x
  slower here, so every division in a kernel is guarded, and kernels report a status, never raise.

Cache safety and cache keys: numba keys its on-disk cache on each function's own source file, not
on the module-level constants it imports (the lane layout, for instance), so a stale kernel could
survive a layout change. The cache therefore lives in a directory named after a digest of every
source file of `twin/`, so any change of the engine's code compiles afresh. Both that digest and
numba's per-file stamp (`StrippedSourceLocator`) are taken over the files' syntax trees without
their string statements (the docstrings, attribute docstrings included; comments never reach the
tree), and a kernel is told apart from its namesakes by its own code rather than its line number:
editing a docstring or a comment keeps the compiled cache.
"""

import ast
import hashlib
import inspect
import json
import os
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numba
from numba.core import caching

# the package whose kernels the stripped-source locator serves and whose code names the cache
ENGINE_ROOT = Path(__file__).resolve().parent


def _is_string_statement(node: ast.AST) -> bool:
    return isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str)


def _strip_docstrings(tree: ast.AST) -> ast.AST:
    """The tree without its string statements: the docstrings of the module, classes and
    functions, and the attribute docstrings after an assignment (a bare string literal does
    nothing when run)."""
    for node in ast.walk(tree):
        for field in ("body", "orelse", "finalbody"):
            body = getattr(node, field, None)
            if isinstance(body, list) and body and isinstance(body[0], ast.AST):
                kept = [st for st in body if not _is_string_statement(st)]
                if len(kept) != len(body):
                    setattr(node, field, kept or [ast.Pass()])
    return tree


def code_digest(source: str) -> bytes:
    """SHA-256 of a piece of Python source's syntax tree without docstrings and comments."""
    tree = _strip_docstrings(ast.parse(source))
    return hashlib.sha256(ast.dump(tree, include_attributes=False).encode()).digest()


# The digests of the source files, kept between runs in the cache's base directory keyed by each
# file's (mtime in ns, size), so a command does not parse every file of twin/ at each start
# (about 0.3 s); a file edited since has another stamp and is digested again.
DIGEST_MEMO_FILE = "source-digests.json"
_digests: dict[str, tuple[int, int, str]] = {}  # path -> (st_mtime_ns, st_size, code digest hex)
_digests_changed = False


def _cache_base_dir() -> str:
    return os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "bearing-twin"
    )


def _load_digest_memo(path: str) -> dict[str, tuple[int, int, str]]:
    """The memo written by an earlier run; empty when it is missing or unreadable."""
    try:
        with open(path, encoding="utf-8") as f:
            raw = json.load(f)
        return {k: (int(v[0]), int(v[1]), str(v[2])) for k, v in raw.items()}
    except (OSError, ValueError, TypeError, IndexError, AttributeError):
        return {}


def _save_digest_memo(path: str) -> None:
    """Write the memo (atomically: a concurrent reader sees the old file or the new one); a
    read-only cache directory only costs the next run the parsing."""
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        tmp = f"{path}.{os.getpid()}.tmp"
        kept = {k: v for k, v in _digests.items() if os.path.exists(k)}  # checkouts since removed
        with open(tmp, "w", encoding="utf-8") as f:
            json.dump(kept, f)
        os.replace(tmp, path)
    except OSError:
        pass


def _file_digest(path: str, st_mtime_ns: int, st_size: int) -> bytes:
    """`code_digest` of a source file, memoised by (path, mtime, size): a file edited while the
    process runs, or between runs, is digested again."""
    global _digests_changed
    known = _digests.get(path)
    if known is not None and known[0] == st_mtime_ns and known[1] == st_size:
        return bytes.fromhex(known[2])
    digest = code_digest(Path(path).read_text(encoding="utf-8"))
    _digests[path] = (st_mtime_ns, st_size, digest.hex())
    _digests_changed = True
    return digest


# numba's cache classes (public names since numba 0.63, underscored before)
_CACHE_IMPL = getattr(caching, "CacheImpl", None) or caching._CacheImpl  # type: ignore[attr-defined]
if TYPE_CHECKING:
    from numba.core.caching import UserProvidedCacheLocator as _UserLocator
else:
    _UserLocator = getattr(caching, "UserProvidedCacheLocator", None) or caching._UserProvidedCacheLocator


class StrippedSourceLocator(_UserLocator):
    """numba's locator for `numba.config.CACHE_DIR`, stamped with the digest of the source file's
    code (`code_digest`) instead of its bytes, and disambiguated by the digest of the function's
    own code instead of its first line number."""

    def __init__(self, py_func, py_file):
        super().__init__(py_func, py_file)
        try:
            own = textwrap.dedent(inspect.getsource(py_func))
            self._own_code = code_digest(own).hex()[:16]
        except (OSError, TypeError, SyntaxError):
            self._own_code = str(self._lineno)

    def get_source_stamp(self):
        st = os.stat(self._py_file)
        return _file_digest(self._py_file, st.st_mtime_ns, st.st_size)

    def get_disambiguator(self):
        return self._own_code

    @classmethod
    def from_function(cls, py_func, py_file):
        if not py_file.startswith(str(ENGINE_ROOT)):
            return None
        return super().from_function(py_func, py_file)


def _engine_cache_dir() -> str:
    """`<cache base>/numba-<digest of the code of every source file of twin/>`; the files'
    digests come from the memo of earlier runs where their stamps match, and the memo is
    written back when a file had to be digested."""
    base = _cache_base_dir()
    memo = os.path.join(base, DIGEST_MEMO_FILE)
    _digests.update(_load_digest_memo(memo))
    root = ENGINE_ROOT
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        digest.update(path.relative_to(root).as_posix().encode())
        st = path.stat()
        digest.update(_file_digest(str(path), st.st_mtime_ns, st.st_size))
    if _digests_changed:
        _save_digest_memo(memo)
    return os.path.join(base, f"numba-{digest.hexdigest()[:16]}")


numba.config.CACHE_DIR = _engine_cache_dir()  # type: ignore[attr-defined]  # numba.config sets its options at run time


def engine_cache_is_empty() -> bool:
    """Whether no kernel of this engine version is in its cache yet (numba's index files, `.nbi`):
    its first run then compiles them, a minute or two, which a command says before it waits."""
    for _root, _dirs, files in os.walk(numba.config.CACHE_DIR):  # type: ignore[attr-defined]
        if any(name.endswith(".nbi") for name in files):
            return False
    return True


if StrippedSourceLocator not in _CACHE_IMPL._locator_classes:
    _CACHE_IMPL._locator_classes.insert(0, StrippedSourceLocator)

JIT: dict[str, Any] = dict(nogil=True, cache=True)

# Branch-free array loops (contact lanes) use numpy's error model so that divisions carry no
# zero check and LLVM can vectorise them; their inputs never divide by zero (the ball centre is
# never on the bearing axis nor on the groove-centre circle).
JIT_VECTOR: dict[str, Any] = dict(JIT, error_model="numpy")

# The step (`twin.kernels.step.step_n`): numpy's error model too, so that the lane passes inlined
# into it (numba-level `inline="always"`: no array crosses a call inside the loop, hence no
# reference counting per pass) keep their vectorised form, and without numba's reference-counted
# runtime (`_nrt=False`: the step allocates nothing, and the arrays it is given outlive the call;
# with it, every inlined pass counted its array arguments up and down with atomic operations,
# ~6 % of the step); a division by zero gives inf / NaN,
# which the step's finiteness check reports as a status (python's model would raise instead).
JIT_STEP: dict[str, Any] = dict(JIT_VECTOR, _nrt=False)
