"""Convergence study of the time step: the auto step against 1 us over the envelope.

Every case runs three times from the same warm start, at the seed's 1 us, at `time_step_s =
"auto"` (`twin.timestep`) and at twice auto, settles for SETTLE_S, then averages its outputs over
whole cage revolutions (at least MIN_WINDOW_S): per race, the ball load, Lambda, h_min and mu
against azimuth (AZIMUTH_BINS bins over the balls' actual azimuths), the cage speed, the balls'
spin and orbital speeds, the friction torque (the torque the shaft supplies, averaged over every
step), the bearing's impedance magnitude |Z| (always defined), its capacitance where the snapshot
publishes one (the network is capacitive: the mean over the samples that publish it, compared when
both runs publish it in every sample, else null) and, with a shaft current, the current-heating
temperature rise.
The deviations from 1 us are checked against TOLERANCES (0.5 % for loads, films,
Lambda and speeds, 2 % for torque and electrical values; mu, a film value, is held to 0.5 %).

How a deviation is measured: loads as the largest change of a bin's mean load relative to the
largest mean load of the race (the edge of the loaded zone carries almost no load, a relative
change there says nothing); Lambda, h_min and mu relative in each bin where the contact is closed
in every sample of both runs, and so are its two neighbours: in the bins where a contact closes
or opens the load passes through zero, where Lambda ~ Q^-0.073 is singular, and a bin's mean there
depends on the instant of first contact within a step and a tribology period (seen: 2 % on Lambda
at the edge bin, 0.01 % one bin inside). That per bin in the loaded zone (mean load at least
LOADED_FRACTION of the peak); in the unloaded zone, where the outer contact carries only the
centrifugal force (under 1 % of the peak) and the balls rattle between cage and outer ring, the
mean over its bins: per bin, that zone's one-revolution means scatter by up to 0.1 % (Lambda) and
0.8 % (mu, on the steep end of the Stribeck line near Lambda = 3) between 1 us and 0.5 us already,
i.e. it is sampling noise of the rattling, not an effect of the step. Scalars relative.

`stability_study` checks the critical step itself: at the static capacity (the largest radial
load the model accepts) and 10 rad/s, the auto step must run and a step 20 % above the critical
one must diverge (the kernel's penetration or finiteness status), i.e. the estimate is a real
bound and not a loose one.

No I/O here: `bearing-twin timestep-study` prints the tables.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from typing import Literal

import numpy as np

from twin import catalog, timestep
from twin.engine import Twin
from twin.kernels import layout as L
from twin.model import make_model
from twin.setpoint import Setpoint
from twin.spec import ModelOptions

REFERENCE_TIME_STEP_S = 1e-6  # seed 000's step
SETTLE_S = 0.02  # after the warm start, before averaging [s] (two thermal refreshes)
MIN_WINDOW_S = 0.03  # at least this many seconds of whole cage revolutions [s]
SAMPLES_PER_REVOLUTION = 360
ELECTRICAL_EVERY_SAMPLES = 10  # the bearing network is evaluated every this many samples
AZIMUTH_BINS = 36
MIN_BIN_SAMPLES = 3
LOADED_FRACTION = 0.05  # bins with a mean load above this fraction of the peak: loaded zone
TOLERANCES = {  # relative
    "ball_load": 0.005,
    "lambda": 0.005,
    "h_min": 0.005,
    "mu": 0.005,
    "cage_speed": 0.005,
    "ball_spin": 0.005,
    "ball_orbital_speed": 0.005,
    "friction_torque": 0.02,
    "impedance": 0.02,
    "capacitance": 0.02,
    "current_heating": 0.02,
}
QUANTITIES = tuple(TOLERANCES)


@dataclass(frozen=True)
class Case:
    """One operating point of the envelope (SI; clearance negative = preload)."""

    id: str
    designation: str
    shaft_speed_rad_s: float
    radial_load_n: float
    axial_load_n: float = 0.0
    diametral_clearance_m: float = 0.0
    shaft_current_a: float = 0.0


def _family_7208() -> list[str]:
    """The 7208 designations of the catalog (7208, and 7208AC / 7208C where the catalog has them)."""
    return [d for d in catalog.designations() if d.startswith("7208")]


def envelope_cases() -> list[Case]:
    """The operating envelope: 6208, 6205, the 7208 family; 100-1700 rad/s; 750-7500 N;
    clearance and preload; with and without shaft current."""
    cases = [
        Case("6208-serve", "6208", 500.0, 3000.0),
        Case("6208-100rad-3kN", "6208", 100.0, 3000.0),
        Case("6208-1700rad-3kN", "6208", 1700.0, 3000.0),
        Case("6208-500rad-750N", "6208", 500.0, 750.0),
        Case("6208-500rad-7.5kN", "6208", 500.0, 7500.0),
        Case("6208-1700rad-7.5kN", "6208", 1700.0, 7500.0),
        Case("6208-100rad-750N", "6208", 100.0, 750.0),
        Case("6208-clearance", "6208", 500.0, 3000.0, diametral_clearance_m=12.6e-6),
        Case("6208-preload", "6208", 500.0, 3000.0, diametral_clearance_m=-12.6e-6),
        Case("6208-5A", "6208", 500.0, 3000.0, shaft_current_a=5.0),
        Case("6208-1700rad-20A", "6208", 1700.0, 3000.0, shaft_current_a=20.0),
        Case("6205-500rad-3kN", "6205", 500.0, 3000.0),
        Case("6205-1700rad-750N", "6205", 1700.0, 750.0),
        Case("6205-100rad-7.5kN", "6205", 100.0, 7500.0),
    ]
    for d in _family_7208():
        cases.append(Case(f"{d}-500rad-3kN+3kN", d, 500.0, 3000.0, axial_load_n=3000.0))
    cases += [
        Case("7208-1700rad-7.5kN+3kN", "7208", 1700.0, 7500.0, axial_load_n=3000.0),
        Case("7208-100rad-750N+750N", "7208", 100.0, 750.0, axial_load_n=750.0),
        Case("7208-preload", "7208", 500.0, 3000.0, axial_load_n=3000.0, diametral_clearance_m=-10e-6),
    ]
    return cases


def quick_cases() -> list[Case]:
    """A subset for the test suite: the serve default, a combined-load 7208 with preload, a
    fast loaded 6205, and a shaft current."""
    keep = {"6208-serve", "7208-preload", "6205-1700rad-750N", "6208-5A"}
    return [c for c in envelope_cases() if c.id in keep]


@dataclass
class _Run:
    """Averaged outputs of one run."""

    time_step_s: float
    status: str
    restarts: int
    window_s: float
    load: np.ndarray  # (2, bins) mean load per azimuth bin [N]
    lam: np.ndarray  # (2, bins) mean over closed samples
    h_min: np.ndarray
    mu: np.ndarray
    closed: np.ndarray  # (2, bins) bool: closed in every sample, enough samples
    scalars: dict


def run_case(case: Case, time_step_s: float | Literal["auto"], **options) -> _Run:
    """Warm start, settle, average over whole cage revolutions at the given step (`options`:
    further ModelOptions fields)."""
    twin = Twin(
        case.designation,
        options=ModelOptions(time_step_s=time_step_s, **options),
        setpoint=Setpoint(
            shaft_speed_rad_s=case.shaft_speed_rad_s,
            radial_load_n=case.radial_load_n,
            axial_load_n=case.axial_load_n,
            shaft_current_a=case.shaft_current_a,
        ),
        diametral_clearance_m=case.diametral_clearance_m,
    )
    dt = twin.model.dt_s
    restarts0 = twin.restarts
    twin.advance(SETTLE_S, max_restarts=1)
    period = 2.0 * math.pi / max(twin.model.cage_speed_rad_s(case.shaft_speed_rad_s), 1e-3)
    revolutions = max(1, math.ceil(MIN_WINDOW_S / period - 1e-9))
    total_steps = int(round(revolutions * period / dt))
    n_samples = SAMPLES_PER_REVOLUTION * revolutions
    b = AZIMUTH_BINS
    load_sum = np.zeros((2, b))
    count = np.zeros((2, b))
    closed_count = np.zeros((2, b))
    lam_sum = np.zeros((2, b))
    h_sum = np.zeros((2, b))
    mu_sum = np.zeros((2, b))
    cage = spin = orbit = 0.0
    torque_sum = torque_steps = 0.0
    cap_sum = heat_sum = imp_sum = 0.0
    cap_n = elec_n = 0
    s = twin.state
    done = 0
    samples = 0
    for k in range(1, n_samples + 1):
        target = int(round(k * total_steps / n_samples))
        n = target - done
        if n <= 0:
            continue
        twin.advance(n * dt, frame_steps=n, max_restarts=1)
        done = target
        if twin.restarts > restarts0:  # diverged at this step: no averages to compare
            break
        torque_sum += s.scalars[L.X_TORQUE_SUM]
        torque_steps += s.scalars[L.X_TORQUE_COUNT]
        x = s.ball_position_in_bearing_m
        v = s.ball_velocity_in_bearing_m_s
        az = np.arctan2(x[:, 1], x[:, 0])
        idx = np.floor((az + math.pi) / (2.0 * math.pi) * b).astype(int) % b
        c = s.contacts
        for r in range(2):
            q = c[L.C_LOAD, r::2]
            on = q > 0.0
            np.add.at(load_sum[r], idx, q)
            np.add.at(count[r], idx, 1.0)
            np.add.at(closed_count[r], idx, on.astype(float))
            np.add.at(lam_sum[r], idx, np.where(on, c[L.C_LAMBDA, r::2], 0.0))
            np.add.at(h_sum[r], idx, np.where(on, c[L.C_H_MIN, r::2], 0.0))
            np.add.at(mu_sum[r], idx, np.where(on, c[L.C_MU, r::2], 0.0))
        cage += s.scalars[L.X_CAGE_SPEED]
        spin += float(np.mean(np.linalg.norm(s.ball_angular_velocity_rad_s, axis=1)))
        rho2 = x[:, 0] ** 2 + x[:, 1] ** 2
        orbit += float(np.mean((x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0]) / rho2))
        samples += 1
        if samples % ELECTRICAL_EVERY_SAMPLES == 0:
            e = twin.snapshot().electrical
            imp_sum += e.impedance_ohm
            heat_sum += e.current_temperature_rise_k
            elec_n += 1
            if e.capacitance_f is not None:  # published only where the network is capacitive
                cap_sum += e.capacitance_f
                cap_n += 1
    samples = max(samples, 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        closed_n = np.maximum(closed_count, 1.0)
        run = _Run(
            time_step_s=dt,
            status=twin.status,
            restarts=twin.restarts - restarts0,
            window_s=total_steps * dt,
            load=load_sum / np.maximum(count, 1.0),
            lam=lam_sum / closed_n,
            h_min=h_sum / closed_n,
            mu=mu_sum / closed_n,
            closed=(closed_count == count) & (count >= MIN_BIN_SAMPLES),
            scalars={
                "cage_speed": cage / samples,
                "ball_spin": spin / samples,
                "ball_orbital_speed": orbit / samples,
                "friction_torque": torque_sum / max(torque_steps, 1.0),
                "impedance": imp_sum / max(elec_n, 1),
                "capacitance": cap_sum / cap_n if cap_n else math.nan,
                "capacitive_everywhere": cap_n == elec_n > 0,
                "current_heating": heat_sum / max(elec_n, 1),
            },
        )
    return run


def _relative(a: float, ref: float) -> float:
    if a == ref:
        return 0.0
    return abs(a - ref) / abs(ref) if ref != 0.0 else math.inf


def compare(run: _Run, ref: _Run, with_current: bool) -> dict[str, float]:
    """Largest relative deviation of each quantity of `run` from `ref` (see the module doc)."""
    out = {}
    peak = ref.load.max(axis=1)
    out["ball_load"] = float(np.max(np.abs(run.load - ref.load).max(axis=1) / peak))
    both = run.closed & ref.closed
    both = both & np.roll(both, 1, axis=1) & np.roll(both, -1, axis=1)  # not the bins where it closes/opens
    zone = ref.load >= LOADED_FRACTION * peak[:, None]
    for key, a, r in (("lambda", run.lam, ref.lam), ("h_min", run.h_min, ref.h_min), ("mu", run.mu, ref.mu)):
        worst = []
        loaded = both & zone
        if loaded.any():  # every bin of the loaded zone
            worst.append(float(np.max(np.abs(a[loaded] - r[loaded]) / np.abs(r[loaded]))))
        for race in range(2):  # the unloaded zone's mean (centrifugal load only, balls rattle)
            free = both[race] & ~zone[race]
            if free.any():
                worst.append(_relative(float(np.mean(a[race, free])), float(np.mean(r[race, free]))))
        out[key] = max(worst) if worst else math.nan
    for key in ("cage_speed", "ball_spin", "ball_orbital_speed", "friction_torque", "impedance"):
        out[key] = _relative(run.scalars[key], ref.scalars[key])
    out["capacitance"] = (
        _relative(run.scalars["capacitance"], ref.scalars["capacitance"])
        if run.scalars["capacitive_everywhere"] and ref.scalars["capacitive_everywhere"]
        else math.nan
    )
    out["current_heating"] = (
        _relative(run.scalars["current_heating"], ref.scalars["current_heating"]) if with_current else math.nan
    )
    return out


def run_study(cases: list[Case] | None = None, *, quick: bool = False, progress=None) -> list[dict]:
    """The study table: one row per case and step (auto, twice auto), each with the step, the
    largest relative deviation from 1 us of every quantity, the tolerances and whether all hold.
    `progress(case, label)` is called before each run if given."""
    cases = cases if cases is not None else (quick_cases() if quick else envelope_cases())
    rows = []
    for case in cases:
        if progress:
            progress(case, "1 us")
        ref = run_case(case, REFERENCE_TIME_STEP_S)
        model = make_model(catalog.bearing(case.designation, diametral_clearance_m=case.diametral_clearance_m))
        auto_dt, crit = model.dt_s, model.time_step.critical_step_s
        steps: tuple[tuple[str, float | Literal["auto"]], ...] = (("auto", timestep.AUTO), ("2x auto", 2.0 * auto_dt))
        for label, dt in steps:
            if progress:
                progress(case, label)
            run = run_case(case, dt)
            dev = compare(run, ref, case.shaft_current_a > 0.0)
            if run.restarts or ref.restarts:  # diverged: nothing to compare
                dev = {q: math.inf for q in QUANTITIES}
            ok = (
                run.status == "ok"
                and ref.status == "ok"
                and run.restarts == 0
                and all(not (dev[q] > TOLERANCES[q]) for q in QUANTITIES)
            )
            rows.append(
                {
                    **asdict(case),
                    "step": label,
                    "time_step_s": run.time_step_s,
                    "critical_time_step_s": crit,
                    "reference_time_step_s": ref.time_step_s,
                    "window_s": run.window_s,
                    "status": run.status,
                    "reference_status": ref.status,
                    "restarts": run.restarts,
                    "deviation": dev,
                    "within_tolerance": ok,
                    "friction_torque_n_m": run.scalars["friction_torque"],
                    "reference_friction_torque_n_m": ref.scalars["friction_torque"],
                    "impedance_ohm": run.scalars["impedance"],
                    "capacitance_f": run.scalars["capacitance"],
                }
            )
    return rows


def summary(rows: list[dict], step: str = "auto") -> dict[str, float]:
    """Largest deviation of each quantity over the rows of one step label."""
    out = {}
    for q in QUANTITIES:
        values = [
            r["deviation"][q]
            for r in rows
            if r["step"] == step and r["deviation"][q] is not None and not math.isnan(r["deviation"][q])
        ]
        out[q] = max(values) if values else math.nan
    return out


_HEAD = (
    "ball_load",
    "lambda",
    "h_min",
    "mu",
    "cage_speed",
    "ball_spin",
    "ball_orbital_speed",
    "friction_torque",
    "impedance",
    "capacitance",
    "current_heating",
)
_TITLE = ("load", "Lambda", "h_min", "mu", "cage", "spin", "orbit", "torque", "abs Z", "C", "heating")


def _pct(x: float | None) -> str:
    if x is None or math.isnan(x):
        return "-"
    return "inf" if math.isinf(x) else f"{100.0 * x:.3f}"


def markdown_table(rows: list[dict]) -> str:
    """The study as a Markdown table: largest deviation from 1 us in %, per case and step."""
    lines = [
        "| case | step | dt [us] | " + " | ".join(_TITLE) + " | within |",
        "|---|---|---|" + "---|" * len(_TITLE) + "---|",
    ]
    for r in rows:
        cells = [_pct(r["deviation"][q]) for q in _HEAD]
        verdict = "yes" if r["within_tolerance"] else ("no" if not r["restarts"] else "no: diverged")
        lines.append(
            f"| {r['id']} | {r['step']} | {r['time_step_s'] * 1e6:.3f} | " + " | ".join(cells) + f" | {verdict} |"
        )
    for step in ("auto", "2x auto"):
        s = summary(rows, step)
        lines.append(f"| **largest** | {step} | | " + " | ".join(_pct(s[q]) for q in _HEAD) + " | |")
    lines.append("| tolerance | | | " + " | ".join(_pct(TOLERANCES[q]) for q in _HEAD) + " | |")
    return "\n".join(lines)


# ---- the critical step itself ---------------------------------------------------------------------
STABILITY_SPEED_RAD_S = 10.0
STABILITY_RUN_S = 0.01
UNSTABLE_FACTOR = 1.2  # x the critical step: must diverge


def stability_study(designations: list[str] | None = None) -> list[dict]:
    """Per bearing at its largest radial load and 10 rad/s: the status of 10 ms at the auto step,
    at the critical step and at UNSTABLE_FACTOR x the critical step."""
    designations = designations or ["6208", "6205", *_family_7208()]
    rows = []
    for d in designations:
        model = make_model(catalog.bearing(d))
        crit = model.time_step
        load = 0.999 * model.max_radial_load_n
        row = {
            "designation": d,
            "radial_load_n": load,
            "shaft_speed_rad_s": STABILITY_SPEED_RAD_S,
            "critical_time_step_s": crit.critical_step_s,
            "limiting_element": crit.limiting_element,
            "auto_time_step_s": crit.auto_time_step_s,
            "static_load_n": crit.static_load_n,
        }
        for key, dt in (
            ("auto", crit.auto_time_step_s),
            ("critical", crit.critical_step_s),
            ("unstable", UNSTABLE_FACTOR * crit.critical_step_s),
        ):
            twin = Twin(
                d,
                options=ModelOptions(time_step_s=dt),
                setpoint=Setpoint(shaft_speed_rad_s=STABILITY_SPEED_RAD_S, radial_load_n=load),
            )
            twin.advance(STABILITY_RUN_S, max_restarts=1)
            row[f"{key}_stable"] = twin.restarts == 0 and twin.status == "ok"
            row[f"{key}_status"] = twin.status
        rows.append(row)
    return rows


def stability_markdown(rows: list[dict]) -> str:
    """The stability check as a Markdown table."""
    lines = [
        "| bearing | radial load [N] | critical step [us] | limiting element | auto [us] | runs at auto | "
        f"at critical | at {UNSTABLE_FACTOR:g} x critical |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        yn = lambda ok: "runs" if ok else "diverges"  # noqa: E731
        lines.append(
            f"| {r['designation']} | {r['radial_load_n']:.0f} | {r['critical_time_step_s'] * 1e6:.3f} | "
            f"{r['limiting_element']} | {r['auto_time_step_s'] * 1e6:.3f} | {yn(r['auto_stable'])} | "
            f"{yn(r['critical_stable'])} | {yn(r['unstable_stable'])} |"
        )
    return "\n".join(lines)


# ---- the whole study, as the command prints it --------------------------------------------------
def run_all(*, quick: bool = False, progress=None) -> dict:
    """Envelope (or quick subset) and stability check: {"cases", "summary", "stability", ...}."""
    rows = run_study(quick=quick, progress=progress)
    stability = stability_study(["6208"] if quick else None)
    return {
        "reference_time_step_s": REFERENCE_TIME_STEP_S,
        "safety_factor": timestep.SAFETY_FACTOR,
        "tolerances": dict(TOLERANCES),
        "quick": quick,
        "cases": rows,
        "summary": {"auto": summary(rows, "auto"), "2x auto": summary(rows, "2x auto")},
        "all_within_tolerance_at_auto": all(r["within_tolerance"] for r in rows if r["step"] == "auto"),
        "stability": stability,
        "stability_as_expected": all(r["auto_stable"] and not r["unstable_stable"] for r in stability),
    }


def markdown(result: dict) -> str:
    """Both tables of `run_all` as Markdown."""
    return (
        "Largest deviation from 1 us [%] over whole cage revolutions\n\n"
        + markdown_table(result["cases"])
        + "\n\nStability at the static capacity (10 rad/s, 10 ms)\n\n"
        + stability_markdown(result["stability"])
    )


def _finite(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    if isinstance(value, np.floating):
        return _finite(float(value))
    if isinstance(value, np.bool_):
        return bool(value)
    return value


def as_json(result: dict) -> str:
    """`run_all`'s result as strict JSON (non-finite deviations, i.e. diverged or undefined, as null)."""
    return json.dumps(_finite(result), allow_nan=False)
