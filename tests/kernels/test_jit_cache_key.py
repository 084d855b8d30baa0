"""The numba cache key (twin.jit): docstrings and comments do not change it, code does.

A docstring edit in twin/ must not cost a recompilation of the engine, and any change of code
must (the cache directory is named after the digest of every source file of twin/)."""

import importlib.util
import os

import numba

from twin import jit
from twin.jit import StrippedSourceLocator, code_digest

SOURCE = '''
"""Module docstring."""
import math


def f(x):
    """Docstring."""
    # a comment
    return math.sqrt(x) + 1.0
'''


def test_docstrings_and_comments_do_not_change_the_digest():
    edited = (
        SOURCE.replace("Docstring.", "Another, longer docstring\n    on two lines.")
        .replace("# a comment", "# another comment\n    # and one more")
        .replace("Module docstring.", "Other.")
    )
    assert code_digest(edited) == code_digest(SOURCE)


def test_code_changes_the_digest():
    assert code_digest(SOURCE.replace("+ 1.0", "+ 2.0")) != code_digest(SOURCE)
    assert code_digest(SOURCE.replace("math.sqrt(x)", "math.sqrt(x + 0.0)")) != code_digest(SOURCE)


def test_kernels_use_the_stripped_source_locator():
    from twin.kernels.step import step_n

    step_n_cache = step_n._cache  # numba's FunctionCache of the dispatcher
    assert isinstance(step_n_cache._impl.locator, StrippedSourceLocator)


KERNEL = '''"""A copied kernel module."""
from numba import njit

from twin.jit import JIT

SCALE = 1.0
"""Scale of the force [-]."""


@njit(**JIT)
def spring_force_n(stiffness_n_m, deflection_m):
    """Linear spring force [N]."""
    return SCALE * stiffness_n_m * deflection_m
'''

KERNEL_DOCS_EDITED = '''"""A copied kernel module,

with a longer docstring."""
from numba import njit

from twin.jit import JIT

# a new comment
SCALE = 1.0
"""Scale of the force, an attribute docstring
over two lines [-]."""


@njit(**JIT)
def spring_force_n(stiffness_n_m, deflection_m):
    """Linear spring force [N]:
    F = k x (Hooke)."""
    # another comment
    return SCALE * stiffness_n_m * deflection_m
'''


def _compile_and_call(tmp_path, name: str):
    """Import the copied kernel module under a new module name (a fresh dispatcher), call it once,
    and return numba's cache statistics for that call: (hits, misses)."""
    spec = importlib.util.spec_from_file_location(name, tmp_path / "engine_copy" / "law.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.spring_force_n(2.0e5, 1.0e-6) == 2.0e5 * 1.0e-6
    stats = module.spring_force_n.stats
    return sum(stats.cache_hits.values()), sum(stats.cache_misses.values())


def test_a_docstring_edit_loads_the_compiled_kernel_from_the_cache(tmp_path, monkeypatch):
    """numba's own cache, end to end, on a kernel module copied into a temporary package served by
    the stripped-source locator: a second import after docstrings and comments are edited (the
    lines shifted, the file's size and time changed) loads the compiled kernel; a code edit
    compiles afresh."""
    package = tmp_path / "engine_copy"
    package.mkdir()
    law = package / "law.py"
    monkeypatch.setattr(jit, "ENGINE_ROOT", package.resolve())
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "cache"))
    law.write_text(KERNEL)
    assert _compile_and_call(tmp_path, "law_first") == (0, 1)  # compiled and saved
    law.write_text(KERNEL_DOCS_EDITED)
    assert KERNEL_DOCS_EDITED.count("\n") >= KERNEL.count("\n") + 5
    assert _compile_and_call(tmp_path, "law_docs_edited") == (1, 0)  # loaded, not compiled
    law.write_text(KERNEL_DOCS_EDITED.replace("SCALE * stiffness_n_m", "stiffness_n_m * SCALE"))
    assert _compile_and_call(tmp_path, "law_code_edited") == (0, 1)


def test_an_empty_engine_cache_is_told_apart(tmp_path, monkeypatch):
    """`serve` says it compiles before its first start's minute of numba compilation
    (twin.jit.engine_cache_is_empty): an engine cache directory without numba's index files
    (`.nbi`), or none at all, is empty; one with an index file in a module's folder is not."""
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "numba-none"))
    assert jit.engine_cache_is_empty()
    folder = tmp_path / "numba-none" / "kernels_0123"
    folder.mkdir(parents=True)
    (folder / "step.step_n-100.py311.1.nbc").write_bytes(b"")
    assert jit.engine_cache_is_empty()  # a compiled object alone is no index
    (folder / "step.step_n-100.py311.nbi").write_bytes(b"")
    assert not jit.engine_cache_is_empty()


def test_source_digests_are_kept_between_runs(tmp_path, monkeypatch):
    """The cache directory's name needs the code digest of every source file of twin/; a run
    takes them from the memo an earlier run wrote (twin.jit.DIGEST_MEMO_FILE) while a file's
    (mtime, size) stamp is unchanged, parses none of them, and digests an edited file again."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(jit, "_digests", {})
    monkeypatch.setattr(jit, "_digests_changed", False)
    first = jit._engine_cache_dir()
    assert (tmp_path / jit.DIGEST_MEMO_FILE).is_file()

    # a later run: a fresh memo in memory, loaded from the file; no file is parsed
    monkeypatch.setattr(jit, "_digests", {})
    monkeypatch.setattr(jit, "_digests_changed", False)
    parsed: list[str] = []
    real_digest = jit.code_digest

    def counting_digest(source: str) -> bytes:
        parsed.append(source)
        return real_digest(source)

    monkeypatch.setattr(jit, "code_digest", counting_digest)
    assert jit._engine_cache_dir() == first
    assert parsed == []

    # an edited file (another stamp) is digested again, and only that one
    one = sorted(jit.ENGINE_ROOT.rglob("*.py"))[0]
    stamp = one.stat()
    memo = jit._digests[str(one)]
    jit._digests[str(one)] = (memo[0] - 1, memo[1], "00" * 32)  # as if the file had changed since
    assert jit._file_digest(str(one), stamp.st_mtime_ns, stamp.st_size) == real_digest(one.read_text("utf-8"))
    assert len(parsed) == 1


def test_an_unreadable_digest_memo_is_rebuilt(tmp_path, monkeypatch):
    """A memo that is not JSON (a crash while another version wrote it) is ignored and replaced."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(jit, "_digests", {})
    monkeypatch.setattr(jit, "_digests_changed", False)
    (tmp_path / jit.DIGEST_MEMO_FILE).write_text("{not json", encoding="utf-8")
    name = jit._engine_cache_dir()
    assert os.path.basename(name) == os.path.basename(jit.numba.config.CACHE_DIR)  # the same digest
    assert len(jit._load_digest_memo(str(tmp_path / jit.DIGEST_MEMO_FILE))) >= 90
