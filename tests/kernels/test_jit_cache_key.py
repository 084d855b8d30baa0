"""The numba cache key (twin.jit): docstrings and comments do not change it, code does.

A docstring edit in twin/ must not cost a recompilation of the engine, and any change of code
must (the cache directory is named after the digest of every source file of twin/)."""

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
    edited = SOURCE.replace("Docstring.", "Another, longer docstring\n    on two lines.").replace(
        "# a comment", "# another comment\n    # and one more").replace("Module docstring.", "Other.")
    assert code_digest(edited) == code_digest(SOURCE)


def test_code_changes_the_digest():
    assert code_digest(SOURCE.replace("+ 1.0", "+ 2.0")) != code_digest(SOURCE)
    assert code_digest(SOURCE.replace("math.sqrt(x)", "math.sqrt(x + 0.0)")) != code_digest(SOURCE)


def test_kernels_use_the_stripped_source_locator():
    from twin.kernels.step import step_n

    step_n_cache = step_n._cache  # numba's FunctionCache of the dispatcher
    assert isinstance(step_n_cache._impl.locator, StrippedSourceLocator)
