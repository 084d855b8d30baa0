"""Shared fixtures. Physics tests cite the seed equation, table or figure they reproduce."""

import importlib.util
import os
from pathlib import Path

import pytest


def _load_support():
    # --import-mode=importlib and no tests/__init__.py: tests/support.py is not importable by
    # name from test modules, so it is loaded by path here and shared as a fixture
    spec = importlib.util.spec_from_file_location("bearing_twin_test_support", Path(__file__).with_name("support.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_SUPPORT = _load_support()

# Functional tests create twins whatever the speed of this shared machine: the service's admission
# by measured capacity (service.core.capacity) is off in the tests unless a test turns it on
# (tests/service/core/test_pool.py checks it with given costs). Served subprocesses that clear the
# BEARING_TWIN_* environment pass this one on (tests/hostile/conftest.py, test_end_to_end.py).
os.environ.setdefault("BEARING_TWIN_ADMISSION", "off")
# Nor do in-process services set their threads' priorities (service.core.priority):
# renicing is one-way, and the pytest process's own threads (clients, waits) would stay reniced behind
# fast-mode twins that keep both cores busy. tests/service/core/test_priority.py checks the priority, with
# its default, in processes of its own.
os.environ.setdefault("BEARING_TWIN_IO_THREAD_NICE", "0")
os.environ.setdefault("BEARING_TWIN_STEPPING_THREAD_NICE", "0")
os.environ.setdefault("BEARING_TWIN_GC_FREEZE", "0")
# Nor do in-process services hold refusals in the tarpit (service.api.middleware.Tarpit): the functional tests
# send invalid requests from one address on purpose, far above a client's error budget.
# tests/hostile/test_tarpit.py checks the tarpit with settings of its own.
os.environ.setdefault(
    "BEARING_TWIN_TARPIT_DELAY_S", "0"
)  # process-wide too: each in-process service would freeze the pytest heap


@pytest.fixture(scope="session")
def support():
    """tests/support.py: `Peer` (zenoh test peer), `ThreadServer` (uvicorn in a thread),
    `wait_for` (bounded polling), `free_port`, `free_endpoint`, `strict_loads`."""
    return _SUPPORT


@pytest.fixture(scope="session", params=("auto", 1e-6), ids=("dt_auto", "dt_1us"))
def time_step(request):
    """ModelOptions.time_step_s of the seed checks: each runs at the auto step (the default,
    twin.timestep) and at seed 000's 1 us, so the auto step is shown to pass every seed check."""
    return request.param
