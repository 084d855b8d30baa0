"""The `CWRU-DE` twin beside the measured CWRU records, as a report section and a figure:
`python -m service.reports.cwru [--out DIR] [--duration S]` writes `cwru_comparison.png` and prints
the Markdown table of `twin.validation.cwru` (the same rows as docs/validation.md).

Per record (healthy, inner race, ball, outer race at 6:00, 3:00 and 12:00; 0 hp, 0.007 in EDM faults,
Case Western Reserve University Bearing Data Center, excerpts in tests/data/cwru): the first 50 ms of
the measured and the simulated acceleration side by side on the same scale, and both envelope
spectra of the 2-5 kHz band (`twin.vibration.indicators.envelope_spectrum`, the analysis of both)
with the record's expected line and its first harmonics marked.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np

from service.reports.figures import pyplot, save

FIGURE = "cwru_comparison.png"
WAVEFORM_S = 0.05


def comparison(duration_s: float = 1.0) -> list[dict[str, Any]]:
    """Measured and simulated signal [m/s^2] and analysis of every record (twin.validation.cwru)."""
    from dataclasses import asdict

    from twin.validation import cwru

    rows: list[dict[str, Any]] = []
    for rec in cwru.RECORDS:
        m, xm = cwru.measured(rec, duration_s)
        s, xs = cwru.simulated(rec, duration_s)
        rows.append(
            {
                "record": rec,
                "measured": (m, xm),
                "twin": (s, xs),
                "row": {"record": rec.number, "condition": rec.condition, "measured": asdict(m), "twin": asdict(s)},
            }
        )
    healthy = next(r for r in rows if r["record"].defect is None)
    for r in rows:
        for side in ("measured", "twin"):
            r["row"][side]["rms_ratio"] = r[side][0].rms_g / healthy[side][0].rms_g
    return rows


def plot_comparison(rows: list[dict[str, Any]], path: str | Path) -> None:
    """One row of three panels per record: measured waveform, twin waveform (same y scale, g),
    and the two envelope spectra [g] up to 12 x shaft with the expected line marked."""
    from twin.validation import cwru
    from twin.vibration.indicators import envelope_spectrum

    plt = pyplot()
    fig, axes = plt.subplots(len(rows), 3, figsize=(16, 2.9 * len(rows)), squeeze=False)
    fs = cwru.SAMPLE_RATE_HZ
    for ax, r in zip(axes, rows):
        rec = r["record"]
        shaft = rec.rpm / 60.0
        xm = r["measured"][1] / cwru.G_M_S2
        xs = r["twin"][1] / cwru.G_M_S2
        n = int(round(WAVEFORM_S * fs))
        lim = 1.05 * max(np.abs(xm[:n]).max(), np.abs(xs[:n]).max())
        for k, (x, who) in enumerate(((xm, "measured"), (xs, "twin"))):
            a = r[who][0]
            ax[k].plot(np.arange(n) / fs * 1e3, x[:n], lw=0.5, color="k" if who == "measured" else "tab:blue")
            ax[k].set(
                ylim=(-lim, lim),
                ylabel="acceleration [g]",
            )
            ax[k].set_title(
                f"{rec.number} {rec.condition}\n{who}: RMS {a.rms_g:.3f} g, kurtosis {a.kurtosis:.2f}", fontsize=9
            )
        ax[0].set_xlabel("time [ms]")
        ax[1].set_xlabel("time [ms]")
        for x, who, color in ((xm, "measured", "k"), (xs, "twin", "tab:blue")):
            f, amp = envelope_spectrum(x, fs, cwru.ENVELOPE_BAND_HZ)
            keep = f <= cwru.LINE_SEARCH_SHAFT[1] * shaft
            ax[2].plot(f[keep], amp[keep], lw=0.7, color=color, label=who)
        if rec.expected is not None:
            line = cwru.PUBLISHED_MULTIPLES[rec.expected] * shaft
            for h in (1, 2, 3):
                if h * line <= cwru.LINE_SEARCH_SHAFT[1] * shaft:
                    ax[2].axvline(
                        h * line,
                        color="tab:red",
                        ls="--" if h == 1 else ":",
                        lw=0.9,
                        label=f"{rec.expected} {line:.1f} Hz" if h == 1 else None,
                    )
        ax[2].set(
            xlabel="frequency [Hz]",
            ylabel="envelope [g]",
            yscale="log",
            title=f"envelope spectrum {cwru.ENVELOPE_BAND_HZ[0]:.0f}-{cwru.ENVELOPE_BAND_HZ[1]:.0f} Hz",
        )
        ax[2].legend(loc="upper right", fontsize=7)
    save(fig, str(path), dpi=80)


def cwru_section(out_dir: str | Path, duration_s: float = 1.0) -> list[str]:
    """The section's Markdown lines and its figure in `out_dir`."""
    from twin.validation import cwru

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows = comparison(duration_s)
    plot_comparison(rows, out / FIGURE)
    return [
        "## Vibration against the CWRU records (`python -m service.reports.cwru`)\n",
        f"`CWRU-DE` at each record's speed against the measured drive-end acceleration, first "
        f"{duration_s:g} s of each; measured / twin in every cell (docs/validation.md says what is "
        "calibrated and why the fault levels are short).\n",
        cwru.markdown([r["row"] for r in rows]),
        "",
        f"![CWRU records beside the twin]({FIGURE})\n",
    ]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m service.reports.cwru", description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="reports", help="directory of the figure (default reports/)")
    parser.add_argument("--duration", type=float, default=1.0, help="seconds of each record and simulation [s]")
    args = parser.parse_args(argv)
    if not (math.isfinite(args.duration) and 0.1 <= args.duration <= 5.0):
        parser.error(f"--duration {args.duration!r}: must be in [0.1, 5] s (the excerpts are 5 s)")
    print("\n".join(cwru_section(args.out, args.duration)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
