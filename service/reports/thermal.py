"""The thermal section of `bearing-twin report`: the start-up transient from cold of the 6208
(ambient 20 degC, 1000 rad/s, 3000 N) with the network in the loop in the accelerated mode, its
curves (node temperatures, inlet viscosity, smallest Lambda, friction torque against thermal time)
beside the time constants the network states, and the steady state of the fixed-point solver
that real heat capacities reach (twin.validation.thermal_studies, twin.validation.thermal_steady)."""

from __future__ import annotations

from pathlib import Path

from service.reports.figures import pyplot, save
from twin.thermal.network import NODE_NAMES
from twin.validation.thermal_steady import steady_operating_point
from twin.validation.thermal_studies import decay_time_constant_s, startup_transient, transient_time_constants_s


def thermal_section(out: Path, quick: bool) -> list[str]:
    """Markdown lines and the figure of the thermal start-up."""
    duration = 1800.0 if quick else 7200.0
    tr = startup_transient(duration_network_s=duration, sample_every_network_s=60.0)
    steady = steady_operating_point("6208", 1000.0, 3000.0, 0.0, 20.0)
    plt = pyplot()
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    minutes = tr.network_time_s / 60.0
    for k, name in enumerate(NODE_NAMES):
        ax[0, 0].plot(minutes, tr.temperatures_c[:, k], label=name.replace("_", " "))
        ax[0, 0].axhline(steady["temperatures_c"][name], lw=0.6, ls=":", color=ax[0, 0].lines[-1].get_color())
    ax[0, 0].set_ylabel("temperature [degC]")
    ax[0, 0].legend(fontsize=8)
    ax[0, 1].plot(minutes, tr.viscosity_pa_s * 1e3)
    ax[0, 1].set_ylabel("inlet viscosity [mPa s]")
    ax[1, 0].plot(minutes, tr.min_lambda)
    ax[1, 0].set_ylabel("smallest Lambda [-]")
    ax[1, 1].plot(minutes, tr.friction_torque_n_m)
    ax[1, 1].set_ylabel("friction torque [N m]")
    for a in ax[1]:
        a.set_xlabel("thermal time [min] (accelerated x1000)")
    fig.suptitle("6208, 1000 rad/s, 3000 N, ambient 20 degC: start-up from cold (dotted: fixed-point steady state)")
    png = out / "thermal_startup.png"
    save(fig, png)
    tau_net = tr.time_constants_s
    tau_coupled = transient_time_constants_s(tr)
    fitted = decay_time_constant_s(tr, NODE_NAMES.index("outer_ring"))
    end = tr.temperatures_c[-1]
    diff = max(abs(end[k] - steady["temperatures_c"][n]) for k, n in enumerate(NODE_NAMES))
    taus = ", ".join(f"{t:.0f}" for t in tau_net[:3])
    coupled = ", ".join(f"{t:.0f}" for t in tau_coupled[:3])
    ends = ", ".join(f"{n} {end[k]:.1f}" for k, n in enumerate(NODE_NAMES))
    steadies = ", ".join(f"{n} {v:.1f}" for n, v in steady["temperatures_c"].items())
    return [
        "## Thermal network: start-up from cold (6208, 1000 rad/s, 3000 N, ambient 20 degC)\n",
        f"![thermal start-up]({png.name})\n",
        f"Network time constants (real heat capacities): {taus} s; with the friction's feedback (heat "
        f"falling as the oil thins) {coupled} s. The outer ring's approach to its end value decays with "
        f"{fitted:.0f} s.\n",
        f"After {duration / 60:.0f} min: {ends} degC; fixed-point steady state: {steadies} degC (largest "
        f"difference {diff:.2f} K). Friction {tr.friction_torque_n_m[1]:.3f} -> {tr.friction_torque_n_m[-1]:.3f} "
        f"N m, viscosity {tr.viscosity_pa_s[0] * 1e3:.1f} -> {tr.viscosity_pa_s[-1] * 1e3:.1f} mPa s, smallest "
        f"Lambda {tr.min_lambda[0]:.2f} -> {tr.min_lambda[-1]:.2f}.\n",
    ]
