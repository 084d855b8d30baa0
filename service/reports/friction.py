"""The friction-torque section of `bearing-twin report`: the twin's friction torque
(traction integrated over the contact ellipses, seed 001 rolling resistance) against the SKF
model for the frictional moment (twin.validation.skf_friction, the public catalogue formula), for the 6208
of seed 000 and the 6210, over 100-1700 rad/s and 750-7500 N, isothermal and with the inlet
shear heating (twin: Murch-Wilson film factor; SKF: its phi_ish).
"""

from __future__ import annotations

from pathlib import Path

from service.reports.figures import pyplot, save
from service.reports.friction_reference import iso15312_markdown, iso15312_rows, skf_markdown, skf_rows
from twin import catalog
from twin.physics import viscosity
from twin.spec import ModelOptions
from twin.validation import skf_friction, studies

# designation: (bore mm, outside diameter mm); the seed oil at 40 degC
BEARINGS = {"6208": (40.0, 80.0), "6210": (50.0, 90.0)}
OIL_TEMPERATURE_C = 40.0


def _grids(quick: bool):
    if quick:
        return (100.0, 500.0, 1700.0), (750.0, 3000.0, 7500.0), ("6208",)
    return (100.0, 300.0, 500.0, 1000.0, 1700.0), (750.0, 1500.0, 3000.0, 5000.0, 7500.0), tuple(BEARINGS)


def _nu_mm2_s() -> float:
    lub = catalog.lubricant()
    return (
        viscosity.kinematic_viscosity_m2_s(
            lub.kinematic_viscosity_40c_m2_s, lub.kinematic_viscosity_100c_m2_s, OIL_TEMPERATURE_C
        )
        * 1e6
    )


def _row(designation: str, speed: float, load: float, nu: float) -> dict:
    bore, od = BEARINGS[designation]
    twin_iso, _ = studies.mean_friction_torque_n_m(speed, load, designation=designation)
    twin_hot, _ = studies.mean_friction_torque_n_m(speed, load, designation=designation, shear_heating=True)
    skf_iso = skf_friction.frictional_moment(designation, bore, od, load, speed, nu, inlet_shear=False)
    skf_hot = skf_friction.frictional_moment(designation, bore, od, load, speed, nu)
    return {
        "speed": speed,
        "load": load,
        "twin_iso": twin_iso,
        "twin_hot": twin_hot,
        "skf_iso": skf_iso.total_n_m,
        "skf_hot": skf_hot.total_n_m,
        "skf_rolling": skf_iso.rolling_n_m,
        "skf_sliding": skf_iso.sliding_n_m,
    }


def friction_section(out_dir: Path, quick: bool) -> list[str]:
    """Markdown lines of the section; writes friction_torque_skf.png into out_dir."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    speeds, loads, designations = _grids(quick)
    nu = _nu_mm2_s()
    results = {}
    for d in designations:
        results[d] = {"speed": [_row(d, w, 3000.0, nu) for w in speeds], "load": [_row(d, 500.0, f, nu) for f in loads]}
    centre = None
    if not quick:  # the centre-point friction (stribeck_line) on the 6208's load sweep, for the slope
        centre = [
            studies.mean_friction_torque_n_m(500.0, f, options=ModelOptions(friction_model="stribeck_line"))[0]
            for f in loads
        ]
    plt = pyplot()
    fig, axes = plt.subplots(len(designations), 2, figsize=(10, 3.6 * len(designations)), squeeze=False)
    for i, d in enumerate(designations):
        for j, (key, x_label, xs) in enumerate(
            (("speed", "shaft speed [rad/s] (3000 N)", speeds), ("load", "radial load [N] (500 rad/s)", loads))
        ):
            ax = axes[i][j]
            rows = results[d][key]
            ax.loglog(xs, [1e3 * r["twin_iso"] for r in rows], "o-", label="twin, isothermal")
            ax.loglog(xs, [1e3 * r["skf_iso"] for r in rows], "s--", label="SKF model, phi_ish = 1")
            ax.loglog(xs, [1e3 * r["twin_hot"] for r in rows], "o-", mfc="none", label="twin, inlet heating")
            ax.loglog(xs, [1e3 * r["skf_hot"] for r in rows], "s--", mfc="none", label="SKF model, phi_ish")
            if key == "load" and d == "6208" and centre is not None:
                ax.loglog(xs, [1e3 * t for t in centre], "x:", color="grey", label="centre-point friction (before)")
            ax.set(xlabel=x_label, ylabel="friction torque [mN m]", title=f"{d}, seed oil at 40 degC")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
    png = "friction_torque_skf.png"
    save(fig, out_dir / png)

    md = [
        "## Friction torque against the SKF model\n",
        "The twin's shaft torque with the traction integrated over strips of every contact ellipse (Heathcote and "
        "spin slip; seed 000 mu(Lambda) x seed 001 eq. A2 asperity share + Eyring / limiting-shear film) and seed "
        "001's rolling resistance, averaged over whole ball passages, against the SKF model for the frictional "
        "moment (catalogue formula, `twin.validation.skf_friction`: M_rr + M_sl, no seals, no oil bath drag; "
        f"kinematic replenishment for oil jet, K_rs = 3e-8), seed oil at 40 degC ({nu:.1f} mm^2/s). "
        "Isothermal: the twin without inlet heating against phi_ish = 1; with inlet heating: the twin's "
        "Murch-Wilson film factor against the catalogue's phi_ish.\n",
        f"![friction torque]({png})\n",
    ]
    for d in designations:
        for key, label in (("speed", "3000 N"), ("load", "500 rad/s")):
            md += [
                f"**{d}, {label}**\n",
                "| speed [rad/s] | load [N] | twin iso [mN m] | SKF iso [mN m] | ratio | twin heated [mN m] | "
                "SKF phi_ish [mN m] | ratio |",
                "|---|---|---|---|---|---|---|---|",
            ]
            for r in results[d][key]:
                md.append(
                    f"| {r['speed']:g} | {r['load']:g} | {1e3 * r['twin_iso']:.1f} | {1e3 * r['skf_iso']:.1f} | "
                    f"{r['twin_iso'] / r['skf_iso']:.2f} | {1e3 * r['twin_hot']:.1f} | {1e3 * r['skf_hot']:.1f} | "
                    f"{r['twin_hot'] / r['skf_hot']:.2f} |"
                )
            md.append("")
        rows = results[d]["load"]
        slope_twin = studies.log_slope(loads, [r["twin_iso"] for r in rows])
        slope_skf = studies.log_slope(loads, [r["skf_iso"] for r in rows])
        line = (
            f"{d}: d ln M / d ln F_r at 500 rad/s over {loads[0]:g}-{loads[-1]:g} N: twin {slope_twin:.2f}, "
            f"SKF {slope_skf:.2f}"
        )
        if d == "6208" and centre is not None:
            line += f", the centre-point friction {studies.log_slope(loads, centre):.2f}"
        md.append(line + ".\n")
    if not quick:
        md += [
            "### Oil bath with inlet heating and kinematic starvation against the SKF model\n",
            "The twin's contact friction (`Twin.contact_friction_torque_n_m`, oil bath to the centre of the lowest "
            "ball, Murch-Wilson inlet heating, kinematic starvation) against M_rr + M_sl with phi_ish phi_rs, "
            "0.02-0.2 C0 (`python -m service.reports.friction_reference`); the twin's ball drag beside it.\n",
            *skf_markdown(skf_rows()),
            "",
            "### ISO 15312 thermal reference speed\n",
            *iso15312_markdown(iso15312_rows()),
            "",
        ]
    md.append(
        "Flooded and isothermal (the upper tables), the twin's torque exceeds the SKF model's at high speed: "
        "its rolling resistance (seed 001) grows with (eta u)^(2/3..3/4). Lubrication.method = 'oil_bath' "
        "starves the film (twin.physics.starvation) and Thermal.shear_heating heats the inlet (Murch-Wilson), "
        "which bring it down (the oil-bath table).\n"
    )
    return md
