"""Report section for the seed-003 point-contact EHL solver (twin.ehl_solver).

`write_ehl_section(out_dir, grid=129, progress=True)` runs the solver and writes three PNGs
(matplotlib, Agg backend) into out_dir, returning a Markdown section that embeds them by
relative file name:

- ``ehl_centre_line_isothermal.png``: pressure p/p_h and film h [nm] along the centre line y = 0
  at three entrainment speeds, isothermal: the exit constriction of the film and the second (exit)
  pressure spike (seed 003 Fig. 5, 0 A curve; Fig. 1 conditions);
- ``ehl_centre_line_current.png``: the same at the default speed with shear heating (eq. 6) and
  current heating (eq. 10) at 0/10/20/30 A: the spike fades and the film thins (seed 003 Fig. 5);
- ``ehl_film_vs_speed.png``: isothermal h_c and h_min against speed, solver and Hamrock-Dowson
  (seed 003 Fig. 1).

service/reports/report.py calls it; it does not depend on anything else of the report.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from service.reports.figures import pyplot, save
from twin.ehl_solver import params as prm
from twin.ehl_solver import solve_point_contact

REPORT_SPEEDS_M_S = (0.832, 2.496, 4.16)  # low end, default, high end of seed 003 Fig. 1
REPORT_CURRENTS_A = (0.0, 10.0, 20.0, 30.0)  # seed 003 Fig. 5
CENTRE_LINE_PNG = "ehl_centre_line_isothermal.png"
CURRENT_PNG = "ehl_centre_line_current.png"
SPEED_PNG = "ehl_film_vs_speed.png"
HD_TOLERANCE = 0.08  # seed 003 Fig. 1: "maximum relative error ... less than 8 %"


def _centre(res):
    """(X = x/a, P = p/p_h, h [nm]) along y = 0."""
    x, p, h = res.centre_line()
    return x / res.hertz["ax_m"], p / res.hertz["p_hertz_pa"], h * 1e9


def _exit_spike(res) -> tuple[float, float]:
    """(P at the exit spike, its X): the largest excess over the dry Hertz profile downstream of
    the centre along y = 0 (the second pressure maximum of seed 003 Fig. 5)."""
    xs, ps, _ = _centre(res)
    hertz = np.sqrt(np.clip(1.0 - xs**2, 0.0, None))
    k = int(np.argmax(np.where(xs > 0.0, ps - hertz, -np.inf)))
    return float(ps[k]), float(xs[k])


def _constriction(res) -> tuple[float, float]:
    """(h [nm], X) of the exit constriction: the film minimum along y = 0."""
    xs, _, h = _centre(res)
    k = int(np.argmin(np.where(np.abs(xs) < 1.5, h, np.inf)))
    return float(h[k]), float(xs[k])


def _line_plot(plt, cases, labels, title, path: Path) -> None:
    fig, (ax_p, ax_h) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True)
    for res, label in zip(cases, labels):
        xs, ps, h = _centre(res)
        (line,) = ax_p.plot(xs, ps, lw=1.2, label=label)
        ax_h.plot(xs, h, lw=1.2, color=line.get_color(), label=label)
        px, xx = _exit_spike(res)
        ax_p.plot([xx], [px], "v", color=line.get_color(), ms=5)
        hc, xc = _constriction(res)
        ax_h.plot([xc], [hc], "^", color=line.get_color(), ms=5)
    xh = np.linspace(-1.0, 1.0, 201)
    ax_p.plot(xh, np.sqrt(1.0 - xh**2), "k:", lw=0.8, label="dry Hertz")
    ax_p.set(ylabel="p / p_h [-]", title=title, ylim=(0.0, None))
    ax_p.legend(fontsize=7, loc="upper left")
    ax_p.annotate("exit spike (v)", xy=(0.02, 0.04), xycoords="axes fraction", fontsize=7)
    top = max(float(np.nanmax(_centre(r)[2][np.abs(_centre(r)[0]) < 0.9])) for r in cases)
    ax_h.set(
        xlabel="X = x / a [-] (rolling direction ->)",
        ylabel="film h [nm] (y = 0)",
        ylim=(0.0, 1.4 * top),
        xlim=(-1.8, 1.4),
    )
    ax_h.annotate("exit constriction (^)", xy=(0.02, 0.9), xycoords="axes fraction", fontsize=7)
    save(fig, path)


def _speed_plot(plt, speeds, results, path: Path) -> None:
    fig, ax = plt.subplots(figsize=(7, 4.2))
    u = np.array(speeds)
    hmin = np.array([r.h_min_m for r in results]) * 1e9
    hc = np.array([r.h_c_m for r in results]) * 1e9
    fine = np.linspace(min(speeds), max(speeds), 60)
    eta0 = results[0].inputs["eta0_pa_s"]
    hd = (
        np.array(
            [
                prm.hamrock_dowson_film_m(
                    prm.LOAD_N,
                    v,
                    rx_m=prm.RX_M,
                    ry_m=prm.RY_M,
                    e_prime_pa=prm.E_PRIME_PA,
                    eta0_pa_s=eta0,
                    alpha_pa_inv=prm.ALPHA_PA_INV,
                )
                for v in fine
            ]
        )
        * 1e9
    )
    ax.plot(fine, hd[:, 0], "k-", lw=1, label="Hamrock-Dowson h_min")
    ax.fill_between(
        fine,
        hd[:, 0] * (1 - HD_TOLERANCE),
        hd[:, 0] * (1 + HD_TOLERANCE),
        color="k",
        alpha=0.08,
        label="+/- 8 % (seed 003 Fig. 1 claim)",
    )
    ax.plot(fine, hd[:, 1], "k--", lw=1, label="Hamrock-Dowson h_c")
    ax.plot(u, hmin, "o", color="C3", label="solver h_min (side lobes)")
    ax.plot(u, hc, "s", color="C0", label="solver h_c")
    ax.set(
        xlabel="entrainment speed [m/s]",
        ylabel="film thickness [nm]",
        title="Isothermal film vs speed, seed 003 Appendix 2 (Fig. 1)",
    )
    ax.legend(fontsize=7)
    save(fig, path)


def write_ehl_section(out_dir: Path, *, grid: int = 129, progress: bool = True) -> str:
    """Run the seed-003 solver (isothermal at REPORT_SPEEDS_M_S, thermal at REPORT_CURRENTS_A and
    the default speed) on a grid x grid mesh, write the PNGs into out_dir and return Markdown."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cases = [("iso", u, 0.0) for u in REPORT_SPEEDS_M_S]
    cases += [("cur", prm.DEFAULT_ENTRAINMENT_SPEED_M_S, i) for i in REPORT_CURRENTS_A]
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(cases), desc="seed 003 EHL solves", unit="solve")
    iso, cur = {}, {}
    try:
        for kind, u, i in cases:
            if kind == "iso":
                iso[u] = solve_point_contact(entrainment_speed_m_s=u, grid=grid, thermal=False)
            else:
                cur[i] = solve_point_contact(entrainment_speed_m_s=u, grid=grid, current_a=i, thermal=True)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()

    plt = pyplot()
    _line_plot(
        plt,
        [iso[u] for u in REPORT_SPEEDS_M_S],
        [f"{u:g} m/s ({u * prm.RPM_PER_M_S:,.0f} rpm)" for u in REPORT_SPEEDS_M_S],
        f"Isothermal centre line y = 0 ({grid} x {grid}), seed 003 Fig. 5 (0 A)",
        out / CENTRE_LINE_PNG,
    )
    _line_plot(
        plt,
        [cur[i] for i in REPORT_CURRENTS_A],
        [f"{i:g} A" for i in REPORT_CURRENTS_A],
        f"Shear + current heating at {prm.DEFAULT_ENTRAINMENT_SPEED_M_S:g} m/s ({grid} x {grid}), seed 003 Fig. 5",
        out / CURRENT_PNG,
    )
    _speed_plot(plt, list(REPORT_SPEEDS_M_S), [iso[u] for u in REPORT_SPEEDS_M_S], out / SPEED_PNG)

    def nm(v: float) -> str:
        return "-" if not math.isfinite(v) else f"{v * 1e9:.1f}"

    md = [
        "## Point-contact EHL solver (seed 003)\n",
        (
            f"FAS-multigrid Reynolds solution (twin.ehl_solver) at the Appendix 2 inputs, {grid} x {grid} nodes, "
            f"eta0 = {iso[REPORT_SPEEDS_M_S[0]].inputs['eta0_pa_s']:.3g} Pa s at "
            f"{prm.BASE_TEMPERATURE_C:g} degC, R_b = {prm.DEFAULT_BEARING_RESISTANCE_OHM:.3g} ohm.\n"
        ),
        "### Film against entrainment speed (seed 003 Fig. 1)\n",
        f"![film vs speed]({SPEED_PNG})\n",
        (
            "| speed [m/s] | Moes M | h_c [nm] | HD h_c [nm] | h_min [nm] | HD h_min [nm] | h_min error | "
            "h_c/h_min | converged |"
        ),
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for u in REPORT_SPEEDS_M_S:
        r = iso[u]
        m, _ = prm.moes_parameters(
            prm.LOAD_N,
            u,
            rx_m=prm.RX_M,
            e_prime_pa=prm.E_PRIME_PA,
            eta0_pa_s=r.inputs["eta0_pa_s"],
            alpha_pa_inv=prm.ALPHA_PA_INV,
        )
        err = r.h_min_m / r.hamrock_dowson_h_min_m - 1.0
        md.append(
            f"| {u:g} | {m:.0f} | {nm(r.h_c_m)} | {nm(r.hamrock_dowson_h_c_m)} | {nm(r.h_min_m)} | "
            f"{nm(r.hamrock_dowson_h_min_m)} | {100 * err:+.1f} % | {r.h_c_m / r.h_min_m:.2f} | "
            f"{'yes' if r.converged else 'no: ' + r.message} |"
        )
    if grid < 257:
        md.append(
            f"\n{grid} x {grid} nodes do not resolve the side lobes at the low speeds (high M): h_min "
            "is then below its grid-converged value; the numbers quoted below are those of 257 x 257."
        )
    md += [
        (
            "\nSeed 003 claims h_min within 8 % of Hamrock-Dowson (HD) over 0.832-4.16 m/s and notes that the "
            "agreement degrades below 2.5 m/s. On 257 x 257 the solver's central film follows HD within 4 %; "
            "its minimum film "
            "(in the side lobes) is within 8 % only at the upper speeds: at the high Moes loads M of the "
            "low speeds the grid-converged h_c/h_min ratio (2.0-2.4) exceeds HD's nearly fixed 1.76 (HD fitted "
            "34 cases over one decade of load; later numerical studies find the ratio spanning 1 to over 3 with "
            "M and L). The gap is HD's, not the grid's: 513 x 513 nodes move h_min by at most 1.1 % from "
            "257 x 257; see twin/ehl_solver/solver.py.\n"
        ),
        "### Centre-line pressure and film, isothermal (seed 003 Fig. 5, 0 A)\n",
        f"![centre line]({CENTRE_LINE_PNG})\n",
        "| speed [m/s] | exit spike p/p_h | at X | exit constriction h [nm] | at X |",
        "|---|---|---|---|---|",
    ]
    for u in REPORT_SPEEDS_M_S:
        ps, xs = _exit_spike(iso[u])
        hc_, xc = _constriction(iso[u])
        md.append(f"| {u:g} | {ps:.3f} | {xs:.3f} | {hc_:.1f} | {xc:.3f} |")
    md += [
        (
            "\nThe film is flat over the Hertzian zone and closes into the exit constriction; the pressure "
            "follows the dry Hertz profile and rises again into the second (exit) spike just upstream of it.\n"
        ),
        f"### Current heating at {prm.DEFAULT_ENTRAINMENT_SPEED_M_S:g} m/s (seed 003 Fig. 5)\n",
        f"![current]({CURRENT_PNG})\n",
        (
            "| current [A] | eq. 10 rise [K] | mean rise [K] | h_c [nm] | h_min [nm] | h_min reduction vs "
            "isothermal | exit spike p/p_h | converged |"
        ),
        "|---|---|---|---|---|---|---|---|",
    ]
    ref = iso.get(prm.DEFAULT_ENTRAINMENT_SPEED_M_S)
    for i in REPORT_CURRENTS_A:
        r = cur[i]
        red = 1.0 - r.h_min_m / ref.h_min_m if ref is not None else float("nan")
        ps, _ = _exit_spike(r)
        md.append(
            f"| {i:g} | {r.current_temperature_rise_k:.1f} | {r.temperature_rise_k:.1f} | {nm(r.h_c_m)} | "
            f"{nm(r.h_min_m)} | {100 * red:.1f} % | {ps:.3f} | {'yes' if r.converged else 'no: ' + r.message} |"
        )
    md.append(
        "\nWith current the inlet and the contact heat up (eqs. 6 + 10 in Roelands, eq. 3): the film thins, "
        "and the exit spike flattens and moves towards the exit, almost gone at 30 A, as seed 003 Fig. 5 "
        "describes. R_b is anchored on Fig. 2's 84.8 % reduction at 30 A (257 x 257 grid).\n"
    )
    return "\n".join(md) + "\n"
