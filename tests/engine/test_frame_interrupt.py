"""Twin.interrupt_frame, for setpoint latency: a frame in progress ends at its next step
boundary when the runner has an outside input waiting, and the shorter frame changes nothing
but where the frame boundary lies.

The kernel reads the request (setpoint vector slot S_STOP) at the top of every step after the
first; the leapfrog closes the frame with the same half kick as any frame, so a frame of n steps
cut after one step and finished by a frame of n - 1 gives the state of the uncut frame to
rounding: the figures below are within 1e-9 of the largest load and of the ring displacement
(measured 1e-13 .. 1e-12: one extra rounding of a half kick, amplified over 5 ms by the
trajectory's own sensitivity, as in test_step_reference)."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

from twin.engine import Twin
from twin.kernels import layout as L


def _twin():
    tw = Twin("6208")
    tw.advance(0.002)
    return tw


def test_an_interrupt_asked_before_the_frame_ends_it_after_one_step():
    tw = _twin()
    n = round(0.005 / tw.model.dt_s)
    step0 = int(tw.state.scalars[L.X_STEP])
    tw.interrupt_frame()
    left = tw.advance(n * tw.model.dt_s, frame_steps=n)
    assert tw.frame_interrupted and left == n - 1
    assert int(tw.state.scalars[L.X_STEP]) == step0 + 1
    assert tw.status == "ok" and tw.restarts == 0
    tw.clear_frame_interrupt()
    assert tw.advance(n * tw.model.dt_s, frame_steps=n) == 0 and not tw.frame_interrupted
    assert int(tw.state.scalars[L.X_STEP]) == step0 + 1 + n


def test_a_cut_frame_and_its_rest_give_the_state_of_the_whole_frame():
    whole, cut = _twin(), _twin()
    n = round(0.005 / whole.model.dt_s)
    whole.advance(n * whole.model.dt_s, frame_steps=n)
    cut.interrupt_frame()
    left = cut.advance(n * cut.model.dt_s, frame_steps=n)
    cut.clear_frame_interrupt()
    assert cut.advance(left * cut.model.dt_s, frame_steps=n) == 0
    a, b = whole.state, cut.state
    assert b.scalars[L.X_TIME] == pytest.approx(a.scalars[L.X_TIME], rel=1e-12)
    load_a, load_b = a.contacts[L.C_LOAD], b.contacts[L.C_LOAD]
    assert np.abs(load_b - load_a).max() <= 1e-9 * load_a.max()
    ring_a, ring_b = np.asarray(a.inner_ring_offset_m), np.asarray(b.inner_ring_offset_m)
    assert np.abs(ring_b - ring_a).max() <= 1e-9 * np.abs(ring_a).max()


def test_another_thread_interrupts_a_running_frame():
    """The request is written while the kernel runs without the GIL; it must be read inside the
    loop (not once before it). A frame of 1 s of simulated time takes seconds of wall time; it is
    interrupted as soon as it has started."""
    tw = _twin()
    n = round(1.0 / tw.model.dt_s)
    step0 = int(tw.state.scalars[L.X_STEP])
    out = {}
    th = threading.Thread(target=lambda: out.update(left=tw.advance(n * tw.model.dt_s, frame_steps=n)))
    th.start()
    deadline = time.monotonic() + 60.0
    while int(tw.state.scalars[L.X_STEP]) == step0 and time.monotonic() < deadline:
        time.sleep(0.001)
    tw.interrupt_frame()
    th.join(120.0)
    assert not th.is_alive()
    assert tw.frame_interrupted and 0 < out["left"] < n
    assert int(tw.state.scalars[L.X_STEP]) == step0 + n - out["left"]
