"""`bearing-twin report`: rerun seed 000's lubrication studies and seed 001's torque cases, and
write a Markdown report with PNG plots that put the twin's numbers beside the seeds'."""

from __future__ import annotations

import datetime as _dt
import math
from pathlib import Path

import numpy as np
from tqdm import tqdm

from service.reports.figures import pyplot, save
from twin import catalog
from twin.engine import Twin
from twin.kernels import layout as L
from twin.setpoint import Setpoint
from twin.spec import ModelOptions
from twin.validation import studies, timestep_study
from twin.validation import thrust_bearing_seed001 as s001
from twin.validation.bench import run_engine_benchmark

SPEEDS = [100, 300, 500, 700, 900, 1100, 1300, 1500, 1700]
LOADS = [750, 1500, 3000, 4500, 6000, 7500]
CLEARANCES_UM = [-12.6, -6.3, 0.0, 6.3, 12.6]
TABLE_3 = {  # seed 000 Table 3: (inner band, outer band) of Lambda at psi = 0
    "w <= 100": ((0.0, 1.0), (0.0, 1.0)),
    "100 < w <= 1100": ((1.0, 3.0), (1.0, 4.0)),
    "1100 < w <= 1700": ((3.0, 4.0), (4.0, 5.0)),
}


def _band(w: float):
    if w <= 100:
        return TABLE_3["w <= 100"]
    if w <= 1100:
        return TABLE_3["100 < w <= 1100"]
    return TABLE_3["1100 < w <= 1700"]


def _fig_azimuth(out: Path, quick: bool) -> tuple[str, dict]:
    rev = studies.lambda_over_revolution(500.0, 3000.0, samples=120 if quick else 400)
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    deg = np.degrees(rev["azimuth_rad"])
    ax.plot(deg, rev["lambda_outer"], ".", ms=2, label="twin, outer contact")
    ax.plot(deg, rev["lambda_inner"], ".", ms=2, label="twin, inner contact")
    ax.axhline(2.15, color="k", ls="--", lw=1, label="seed 000 Fig. 8: outer at psi = 0 (2.15)")
    ax.axhline(3.0, color="k", ls=":", lw=1, label="seed 000 Fig. 8: outer, unloaded zone (~3)")
    ax.axhspan(1, 3, color="orange", alpha=0.08, label="mixed regime (Table 2)")
    ax.set(xlabel="azimuth psi [deg]", ylabel="film parameter Lambda [-]", title="6208, 500 rad/s, Fr = 3000 N, Pd = 0")
    ax.legend(fontsize=7)
    save(fig, out / "lambda_azimuth_500.png")
    lam = rev["lambda_outer"]
    return "lambda_azimuth_500.png", {"outer_min": float(np.nanmin(lam)), "outer_max": float(np.nanmax(lam))}


def _fig_speed(out: Path, samples) -> tuple[str, float, float]:
    plt = pyplot()
    w = np.array([s.shaft_speed_rad_s for s in samples])
    li = np.array([s.lambda_inner for s in samples])
    lo = np.array([s.lambda_outer for s in samples])
    si, so = studies.log_slope(w, li), studies.log_slope(w, lo)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(w, li, "o-", label=f"twin inner (slope {si:.3f})")
    ax.loglog(w, lo, "s-", label=f"twin outer (slope {so:.3f})")
    ax.loglog(w, li[2] * (w / w[2]) ** 0.6797, "k--", lw=1, label="seed 000 fit, slope 0.6797")
    for y in (1, 3, 4, 5):
        ax.axhline(y, color="grey", lw=0.5)
    ax.set(
        xlabel="shaft speed omega [rad/s]",
        ylabel="Lambda at psi = 0 [-]",
        title="Speed sweep, Fr = 3000 N, Pd = 0 (seed 000 Figs. 11-12)",
    )
    ax.legend(fontsize=8)
    save(fig, out / "lambda_speed.png")
    return "lambda_speed.png", si, so


def _fig_load(out: Path, samples) -> tuple[str, float]:
    plt = pyplot()
    q = np.array([s.load_outer_n for s in samples])
    lo = np.array([s.lambda_outer for s in samples])
    slope = studies.log_slope(q, lo)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(q, lo, "o-", label=f"twin outer (slope {slope:.4f})")
    ax.loglog(q, lo[2] * (q / q[2]) ** -0.0727, "k--", lw=1, label="seed 000 Fig. 9b, slope -0.0727")
    ax.set(
        xlabel="Qmax at psi = 0 [N]",
        ylabel="Lambda_out at psi = 0 [-]",
        title="Radial load 750-7500 N at 500 rad/s (seed 000 Fig. 9)",
    )
    ax.legend(fontsize=8)
    save(fig, out / "lambda_load.png")
    return "lambda_load.png", slope


def _fig_clearance(out: Path, quick: bool, progress) -> tuple[str, list]:
    plt = pyplot()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    rows = []
    for pd_um in CLEARANCES_UM:
        rev = studies.lambda_over_revolution(500.0, 3000.0, pd_um * 1e-6, samples=90 if quick else 250)
        order = np.argsort(rev["azimuth_rad"])
        ax1.plot(
            np.degrees(rev["azimuth_rad"][order]), rev["lambda_outer"][order], ".", ms=2, label=f"Pd = {pd_um:+.1f} um"
        )
        s = studies.sample_at_azimuth_zero(500.0, 3000.0, pd_um * 1e-6)
        rows.append((pd_um, s.epsilon, s.load_outer_n, s.lambda_outer))
        progress.update(1)
    eps = [r[1] for r in rows]
    ax2.plot([r[2] for r in rows], eps, "o-", label="twin eps")
    ax2.plot([r[2] for r in rows], [0.685, None, 0.5, None, 0.4], "k^", label="seed 000 eps (its eq. 2 as printed)")
    ax1.set(xlabel="azimuth [deg]", ylabel="Lambda_out [-]", title="Clearance (seed 000 Fig. 10a)")
    ax2.set(xlabel="Qmax at psi = 0 [N]", ylabel="load parameter eps [-]", title="seed 000 Fig. 10b")
    ax1.legend(fontsize=7)
    ax2.legend(fontsize=7)
    save(fig, out / "lambda_clearance.png")
    return "lambda_clearance.png", rows


def _fig_startup(out: Path, quick: bool) -> tuple[str, dict]:
    """Seed 000 Fig. 7: start-up, steady and slow-down of one ball at 500 rad/s, 3000 N."""
    ramp = 5000.0
    # seed 000's isothermal inlet (Hamrock-Dowson), as the seed computes its Fig. 7
    twin = Twin(
        studies.isothermal_spec(catalog.DEFAULT_DESIGNATION),
        options=ModelOptions(speed_ramp_rad_s2=ramp),
        setpoint=Setpoint(shaft_speed_rad_s=500.0, radial_load_n=3000.0),
    )
    twin.reset(shaft_speed_rad_s=0.0)
    dt_s = 1e-3 if quick else 2.5e-4
    phases = [(0.1, 500.0), (0.1, 500.0), (0.12, 0.0)]
    t, shaft, ball, srr, lam = [], [], [], [], []
    for duration, target in phases:
        twin.set_setpoint(shaft_speed_rad_s=target)
        for _ in range(int(round(duration / dt_s))):
            twin.advance(dt_s)
            t.append(twin.time_s)
            shaft.append(float(twin.state.scalars[L.X_SHAFT_SPEED]))
            ball.append(float(np.linalg.norm(twin.state.ball_angular_velocity_rad_s[0])))
            c = twin.state.contacts[:, 1]
            srr.append(float(twin.state.contacts[L.C_SRR, 0]))
            lam.append(float(c[L.C_LAMBDA]) if c[L.C_LOAD] > 0 else math.nan)
    plt = pyplot()
    fig, (ax1, ax2, ax3) = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
    ax1.plot(t, shaft, label="shaft omega")
    ax1.plot(t, ball, "--", label="ball 0 |omega_ball|")
    ax1.axhline(952.38, color="k", lw=0.5, label="omega Ri / (2 Rb) = 952.38")
    ax2.plot(t, srr)
    ax3.plot(t, lam)
    ax1.set(ylabel="rad/s", title="Start-up, steady, slow-down (seed 000 Figs. 7-8)")
    ax2.set(ylabel="SRR inner, ball 0 [-]")
    ax3.set(ylabel="Lambda_out, ball 0 [-]", xlabel="time [s]")
    ax1.legend(fontsize=7)
    save(fig, out / "startup.png")
    steady = [b for tt, b in zip(t, ball) if 0.15 < tt < 0.2]
    return "startup.png", {"steady_ball_spin": float(np.mean(steady))}


def _fig_seed001(out: Path) -> tuple[str, list]:
    plt = pyplot()
    rows = []
    fig, ax = plt.subplots(figsize=(6, 4))
    cases = [
        ("d = 6.35 mm, Q = 0.125 N, IVR (Table 2)", 6.35e-3, 0.125, "ivr", s001.TABLE_2_D635MM_Q0125N),
        ("d = 3 mm, Q = 0.633 N, transition (Table 1)", 3e-3, 0.633, "transition", s001.TABLE_1_D3MM_Q0633N),
    ]
    for label, d, q, law, table in cases:
        rpm = sorted(table)
        pred = [s001.thrust_torque_seed001(d, q, n, law=law) for n in rpm]
        meas = [s001.measured_torque_n_m(table, n) for n in rpm]
        ax.plot(rpm, [p.torque_n_m * 1e6 for p in pred], "o-", label=f"twin laws: {label}")
        ax.plot(rpm, [m * 1e6 for m in meas], "k^", ms=4)
        for n, p, m in zip(rpm, pred, meas):
            rows.append((label, n, p.torque_n_m, m, (p.torque_n_m - m) / m, p.ehl_share))
    ax.plot([], [], "k^", label="seed 001 measured, K* omega^n")
    ax.set(xlabel="speed [rpm]", ylabel="friction torque [uN m]", title="Seed 001: 3-ball 51205 thrust bearing")
    ax.legend(fontsize=7)
    save(fig, out / "seed001_torque.png")
    return "seed001_torque.png", rows


def write_report(out_dir: str | Path = "reports", quick: bool = False) -> Path:
    """Run every study (with a progress bar) and write `report.md` and PNGs into out_dir."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    from service.reports import ev as report_ev
    from service.reports.angular_contact import angular_contact_section
    from service.reports.cwru import cwru_section
    from service.reports.ehl import write_ehl_section
    from service.reports.friction import friction_section
    from service.reports.thermal import thermal_section
    from service.reports.vibration import vibration_section

    total = len(SPEEDS) + len(LOADS) + len(CLEARANCES_UM) + 10 + report_ev.study_count(quick)
    with tqdm(total=total, desc="bearing-twin report", unit="study") as progress:
        az_png, az = _fig_azimuth(out, quick)
        progress.update(1)
        speed_samples = []
        for w in SPEEDS:
            speed_samples.append(studies.sample_at_azimuth_zero(float(w)))
            progress.update(1)
        load_samples = []
        for fr in LOADS:
            load_samples.append(studies.sample_at_azimuth_zero(500.0, float(fr)))
            progress.update(1)
        speed_png, si, so = _fig_speed(out, speed_samples)
        load_png, sl = _fig_load(out, load_samples)
        cl_png, cl_rows = _fig_clearance(out, quick, progress)
        st_png, st = _fig_startup(out, quick)
        progress.update(1)
        s1_png, s1_rows = _fig_seed001(out)
        progress.update(1)
        ev_md = report_ev.write_ev_section(out, quick, progress)
        ehl_md = write_ehl_section(out, grid=65 if quick else 129, progress=False)
        progress.update(1)
        angular_md = angular_contact_section(out, quick)
        progress.update(1)
        friction_md = friction_section(out, quick)
        progress.update(1)
        bench = run_engine_benchmark(seconds=0.05 if quick else 0.2, cases=False, passes=False)
        progress.update(1)
        step_study = timestep_study.run_all(quick=quick)
        progress.update(1)
        vib_md = vibration_section(out, quick)
        vib_md += cwru_section(out, duration_s=0.5 if quick else 1.0)
        progress.update(1)
        thermal_md = thermal_section(out, quick)
        progress.update(1)

    md = [
        f"# bearing-twin validation report\n\nGenerated {_dt.datetime.now(_dt.UTC):%Y-%m-%d %H:%M UTC}"
        f"{' (quick mode)' if quick else ''}. 6208 of seed 000 Table 1, Hamrock-Dowson film (seed 000 eq. 6), "
        "Stribeck-line friction, eta = 0.04 Pa s, races 0.3 um.\n",
        "## Lambda against azimuth at 500 rad/s (seed 000 Fig. 8)\n",
        f"![azimuth]({az_png})\n",
        f"Outer contact: Lambda from {az['outer_min']:.2f} (loaded, psi = 0) to {az['outer_max']:.2f} "
        "(unloaded zone); seed 000: 2.15 to about 3 (mixed regime everywhere in steady state).\n",
        "## Speed sweep and Table 3 (seed 000 section 3.2)\n",
        f"![speed]({speed_png})\n",
        f"Slope d ln(Lambda_inner) / d ln(omega) = {si:.4f} (seed 000: 0.6797); outer {so:.4f}.\n",
        "| omega [rad/s] | Lambda inner | seed band | Lambda outer | seed band | Q inner [N] | Q outer [N] |",
        "|---|---|---|---|---|---|---|",
    ]
    for s in speed_samples:
        bi, bo = _band(s.shaft_speed_rad_s)
        md.append(
            f"| {s.shaft_speed_rad_s:.0f} | {s.lambda_inner:.2f} | {bi[0]:g}-{bi[1]:g} | {s.lambda_outer:.2f} | "
            f"{bo[0]:g}-{bo[1]:g} | {s.load_inner_n:.0f} | {s.load_outer_n:.0f} |"
        )
    md += [
        "\nTable 3's bands are rounded; the twin's inner Lambda at 1700 rad/s sits on the 4.0 edge.\n",
        "## Radial load 750-7500 N (seed 000 Fig. 9)\n",
        f"![load]({load_png})\n",
        f"Slope d ln(Lambda_out) / d ln(Qmax) = {sl:.4f} (seed 000: -0.0727).\n",
        "## Diametral clearance (seed 000 Fig. 10)\n",
        f"![clearance]({cl_png})\n",
        "| Pd [um] | eps (twin) | Qmax outer [N] | Lambda_out at psi = 0 |",
        "|---|---|---|---|",
    ]
    md += [f"| {pd:+.1f} | {eps:.3f} | {q:.0f} | {lam:.3f} |" for pd, eps, q, lam in cl_rows]
    md += [
        "\nThe seed prints eps = 0.685 / 0.5 / 0.4 for Pd = -12.6 / 0 / +12.6 um; the exact Hertz constants "
        "(docs/physics.md, readings) give 0.684 / 0.500 / 0.402 for the rigid-ring equilibrium, which the twin "
        "reproduces.\n",
        "## Start-up, steady, slow-down (seed 000 Figs. 7-8)\n",
        f"![startup]({st_png})\n",
        f"Steady ball spin {st['steady_ball_spin']:.2f} rad/s (seed 000: 952.38 rad/s).\n",
        "## Seed 001: measured friction torque of the 3-ball 51205 thrust bearing\n",
        f"![seed001]({s1_png})\n",
        "| case | rpm | twin laws [N m] | measured [N m] | deviation | EHL share |",
        "|---|---|---|---|---|---|",
    ]
    md += [f"| {c} | {n} | {p:.3e} | {m:.3e} | {d:+.1%} | {sh:.1%} |" for c, n, p, m, d, sh in s1_rows]
    md += [
        "\nThe measured values include the dry torque (2-12 % of the total, seed 001). Where IVR dominates "
        "(6.35 mm, 0.125 N) Biboulet's IVR force is within 25 % at every speed; where EHL dominates "
        "(3 mm, 0.633 N) the transition force is within 30 % from 120 to 210 rpm and under-predicts by "
        "30-40 % at 60-90 rpm, where the seed's own fits (n = 0.12-0.28) depart from the laws' "
        "omega^0.7 trend.\n",
        *ev_md,
        ehl_md,
        *angular_md,
        *friction_md,
        "## Engine speed\n",
        f"`bearing-twin bench` (6208, 3000 N, 500 rad/s): real-time factor {bench['real_time_factor']:.2f} "
        f"(best of {bench['repeats']}, {bench['ns_per_step']:.0f} ns per step) at the auto step "
        f"dt = {bench['time_step_s'] * 1e6:.3f} us, {bench['real_time_factor_1us']:.2f} at dt = 1 us.\n",
        "## Time step: the auto step against 1 us\n",
        f"{'Quick subset; `bearing-twin timestep-study` runs the whole envelope. ' if quick else ''}"
        "Outputs averaged over whole cage revolutions (twin.validation.timestep_study).\n",
        timestep_study.markdown(step_study) + "\n",
        *vib_md,
        *thermal_md,
    ]
    path = out / "report.md"
    path.write_text("\n".join(md))
    return path
