"""Entity layout and static data (geometry, styles, legends) of a twin; its default blueprint is
service.recording.blueprint.

Entities of one twin, under `bearing/{id}/` (timelines `sim_time`: duration, the twin's simulated
time; `seq`: sequence, the snapshot's `seq`). One entity per quantity, all balls or contacts of a
snapshot in one row (rerun draws one line per instance), sent in chunks of `flush_interval_s`
(per-ball series: `slow_interval_s`) of rows each:

```
geometry/inner_raceway, outer_raceway, pitch_circle   LineStrips3D, static
geometry/load_line            Arrows3D, static: azimuth 0, the radial load line
balls                         Points3D at the ball centres, class id = ball regime (legend below)
loads                         Arrows3D: the inner contact loads, from the ball centres inwards
load_zone/{load_n,lambda,mu}/{inner,outer}
                              BarChart against ball azimuth [deg] (seed 000 Fig. 8): the load zone
                              now, one bar per ball
friction_torque_n_m           Scalars: friction torque [N m]
loads_n                       Scalars: Qmax (largest contact load), radial and axial load [N]
speeds_rad_s                  Scalars: shaft speed setpoint, shaft speed, cage speed [rad/s]
min_lambda                    Scalars: smallest Lambda of the loaded inner / outer contacts [-]
regime_counts                 Scalars: balls in full film, mixed, boundary, without contact
temperatures_c                Scalars: oil temperature setpoint, contact inlet [degC]
thermal/nodes_c, thermal/heat_w   Scalars: the thermal network's node temperatures (shaft, inner ring,
                              balls, outer ring, housing, oil) [degC] and the friction heat by source
                              (rolling, sliding, spin, drag, seal) [W] (ModelOptions.thermal = 'network')
electrical/capacitance_pf     Scalars: bearing capacitance [pF]
electrical/resistance_log10_kohm   Scalars: log10 of R and |Z| [kohm] (decades; no log axes in
                              the viewer); a row without R (no conduction) breaks the line
electrical/shaft_voltage_v, electrical/shaft_current_ma, electrical/film_field_v_per_um,
electrical/current_density_a_per_mm2                              Scalars
electrical/discharge_risk     StateChange (none / possible / likely), one row per change
events                        TextLog: setpoints, scenario state and phase, restarts, fallbacks,
                              status, recording gaps - one row each
alarms/{alarm_id}             TextLog, one row per alarm event (raised, escalated, deescalated,
                              cleared; service.core.alarms): level WARN (warning), CRITICAL
                              (critical), INFO (cleared); the text names the transition, the
                              value, the raise and clear thresholds with their unit
alarm_states/{alarm_id}       StateChange inactive / warning / critical, one row per event (and
                              the active ones again at the start of a new segment)
vibration/acceleration_m_s2   Scalars: the housing accelerometer, one row per sample at its own
                              simulated time (twin with the housing on; about 1.2 MB per
                              simulated second at 51.2 kHz)
vibration/acceleration_rms_peak_m_s2, vibration/velocity_rms_mm_s, vibration/kurtosis
                              Scalars: the indicators of each window (RMS, peak; ISO 20816 velocity
                              RMS; kurtosis, band kurtosis, crest factor), a row per new window
vibration/defect_frequencies_hz   Scalars: FTF, BPFO, BPFI, BSF, 2 x BSF of each window
vibration/envelope_lines_m_s2 Scalars: envelope amplitude at each of them, and the noise floor
vibration/envelope/peaks, vibration/envelope/defect_lines
                              BarChart against frequency [Hz]: the largest envelope peaks of the
                              window, and the envelope amplitude at each defect frequency (the
                              markers); the defects themselves are rows of `events`
vibration/envelope/spectrum   BarChart against frequency [Hz]: the window's full envelope spectrum
                              [m/s^2] (VibrationState.envelope_spectrum: 0 Hz to the peak search's
                              limit at 1 / window_s), a row per new window, bars one bin wide
                              or (range / SPECTRUM_PIXELS), whichever is wider
vibration/envelope/cursor/{FTF,BPFO,BPFI,BSF,2xBSF}
                              BarChart: cursors at 1x, 2x, 3x each defect frequency of the window,
                              as tall as the envelope spectrum (colours of VIB_LINE_RGB)
vibration/spectrum            BarChart: the window's acceleration amplitude spectrum [m/s^2]
                              (VibrationState.amplitude_spectrum: 0 - fs/2, power-summed bins)
vibration/spectrum_envelope_band   BarChart: one translucent bar over the envelope band [Hz]
vibration/measured/{kurtosis,rms_m_s2,crest_factor}/{measured,predicted}
                              Scalars: a measured accelerometer window (service.core.measured)
                              beside the twin's prediction, a row per window at the twin's time
vibration/measured/line_height_db/{BPFO,BPFI,2xBSF}   Scalars: measured line heights [dB]
vibration/measured/alarms     TextLog: what the measurement shows that the twin does not explain
contacts/{load_n,lambda,mu,resistance_log10_kohm,capacitance_pf}
                              Scalars, 2 Z instances (ball 0 inner, ball 0 outer, ball 1 inner,
                              ...): the per-contact series, not in the default layout
```

Alarm rows are placed at the simulated time of the snapshot that caused them (`sim_time`) and
at its `seq` (`AlarmEvent.snapshot_seq`), so they line up with the series of that snapshot.

The annotation context at `bearing/{id}` names the regimes (class ids 0-3); the regime colours
are the same everywhere (balls, `regime_counts`). A value that is undefined (Lambda without
contact, R without conduction) is NaN in a multi-instance row and an empty row (a line break)
in a single-instance one.
"""

from __future__ import annotations

import colorsys
import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import rerun as rr

from service.core.alarm_rules import ALARM_IDS
from twin.snapshot import LAMBDA_KEY

SIM_TIME = "sim_time"
SEQ = "seq"

# regimes: class ids, labels, colours (seed 000 Table 2: Lambda < 1 boundary, 1..3 mixed, > 3 full film)
REGIME_CODE = {"no_contact": 0, "boundary": 1, "mixed": 2, "full_film": 3}
REGIME_LABEL = ("no contact", "boundary", "mixed", "full film")
REGIME_RGB = np.array([[150, 150, 150], [220, 40, 40], [255, 150, 0], [40, 180, 70]], dtype=np.uint8)
REGIME_ORDER = (3, 2, 1, 0)  # order of the regime_counts series: full film first


def _regime_rgb(code: int) -> tuple[int, int, int]:
    red, green, blue = (int(v) for v in REGIME_RGB[code])
    return red, green, blue


INNER_RGB = (60, 120, 255)
OUTER_RGB = (200, 80, 255)
_RACEWAY_RGB = (170, 170, 180)
_PITCH_RGB = (90, 90, 100)
RISK_VALUES = ("none", "possible", "likely")
RISK_RGBA = (0x28B446FF, 0xFF9600FF, 0xDC2828FF)
VIB_LINES = ("ftf", "bpfo", "bpfi", "bsf", "two_bsf")  # VibrationState.defect_frequencies_hz keys
ENVELOPE_BAR_HZ = 12.0  # bar width of the envelope charts [Hz] (visible on a 0-2 kHz axis)
VIB_LINE_LABELS = ("FTF", "BPFO", "BPFI", "BSF", "2 x BSF")
VIB_LINE_RGB = ((150, 150, 150), (230, 60, 60), (80, 160, 255), (0, 200, 120), (255, 170, 0))
CURSOR_NAMES = ("FTF", "BPFO", "BPFI", "BSF", "2xBSF")  # entity names of the envelope cursors (VIB_LINES order)
CURSOR_HARMONICS = 3  # cursors at 1x .. 3x each defect frequency
CURSOR_WIDTH_FRACTION = 400.0  # a cursor is (spectrum range / this) wide, at least 2 bins (~1.5 px)
CURSOR_ALPHA = 150
SPECTRUM_RGB = (40, 70, 150)  # the full spectra's bars
# a spectrum's bars are at least (its range / this) wide: a 1 Hz bin of a 0-2.3 kHz envelope
# spectrum is a quarter of a pixel and would not show; wider bars overlap, the tallest shows
# (what an analyser's display does: the peak of the bins under each pixel)
SPECTRUM_PIXELS = 700.0
ENVELOPE_BAND_RGBA = (255, 170, 0, 40)
WAVEFORM_LEAF = "vibration/acceleration_m_s2"
VIBRATION_SERIES: dict[str, tuple[tuple[str, ...], tuple[tuple[int, int, int], ...]]] = {
    WAVEFORM_LEAF: (("acceleration [m/s^2]",), ((80, 160, 255),)),
    "vibration/acceleration_rms_peak_m_s2": (("RMS [m/s^2]", "peak [m/s^2]"), ((80, 160, 255), (230, 60, 60))),
    "vibration/velocity_rms_mm_s": (("velocity RMS 10-1000 Hz [mm/s]",), ((255, 200, 0),)),
    "vibration/kurtosis": (
        ("kurtosis", "band kurtosis", "crest factor"),
        ((230, 60, 60), (255, 150, 0), (150, 150, 150)),
    ),
    "vibration/defect_frequencies_hz": (VIB_LINE_LABELS, VIB_LINE_RGB),
    "vibration/envelope_lines_m_s2": ((*VIB_LINE_LABELS, "noise floor"), (*VIB_LINE_RGB, (90, 90, 100))),
}
ALARM_STATES = ("inactive", "warning", "critical")
ALARM_STATE_RGBA = (0x28B446FF, 0xFF9600FF, 0xDC2828FF)
ALARM_LOG_LEVEL = {"warning": "WARN", "critical": "CRITICAL", None: "INFO"}

SIDES = ("inner", "outer")
LOAD_ZONE = (
    ("load_n", "contact load Q [N]"),
    (LAMBDA_KEY, "film parameter Lambda [-]"),
    ("mu", "friction coefficient mu [-]"),
)
# per-contact fields: entity leaf, title
CONTACT_SERIES = (
    ("load_n", "contact load [N]"),
    (LAMBDA_KEY, "Lambda [-]"),
    ("mu", "mu [-]"),
    ("resistance_log10_kohm", "log10 R [kohm]"),
    ("capacitance_pf", "C [pF]"),
)

# bearing-level trends (service.recording.trends: a row per window of snapshots, the mean of each
# series): entity leaf -> (series names with their unit, colours)
SERIES: dict[str, tuple[tuple[str, ...], tuple[tuple[int, int, int], ...]]] = {
    "friction_torque_n_m": (("friction torque [N m]",), ((255, 200, 0),)),
    "loads_n": (("Qmax [N]", "Fr setpoint [N]", "Fa setpoint [N]"), ((230, 60, 60), (80, 160, 255), (160, 120, 255))),
    "speeds_rad_s": (
        ("shaft setpoint [rad/s]", "shaft [rad/s]", "cage [rad/s]"),
        ((150, 150, 150), (80, 160, 255), (0, 210, 200)),
    ),
    "min_lambda": (("inner [-]", "outer [-]"), (INNER_RGB, OUTER_RGB)),
    "regime_counts": (tuple(REGIME_LABEL[c] for c in REGIME_ORDER), tuple(_regime_rgb(c) for c in REGIME_ORDER)),
    "temperatures_c": (("oil setpoint [degC]", "contact inlet [degC]"), ((150, 150, 150), (255, 120, 40))),
    "thermal/nodes_c": (
        ("shaft [degC]", "inner ring [degC]", "balls [degC]", "outer ring [degC]", "housing [degC]", "oil [degC]"),
        ((150, 150, 150), INNER_RGB, (255, 120, 40), OUTER_RGB, (120, 90, 60), (230, 200, 40)),
    ),
    "thermal/heat_w": (
        ("rolling [W]", "sliding [W]", "spin [W]", "drag [W]", "seal [W]"),
        ((80, 160, 255), (230, 60, 60), (160, 120, 255), (0, 210, 200), (150, 150, 150)),
    ),
    "electrical/capacitance_pf": (("bearing C [pF]",), ((0, 200, 255),)),
    "electrical/resistance_log10_kohm": (("log10 R [kohm]", "log10 |Z| [kohm]"), ((255, 200, 0), (200, 200, 200))),
    "electrical/shaft_voltage_v": (("shaft voltage [V]", "setpoint [V]"), ((255, 120, 40), (150, 150, 150))),
    "electrical/shaft_current_ma": (("shaft current [mA]", "setpoint [mA]"), ((80, 160, 255), (150, 150, 150))),
    "electrical/film_field_v_per_um": (("largest film field [V/um]",), ((220, 40, 40),)),
    "electrical/current_density_a_per_mm2": (("largest current density [A/mm2]",), ((255, 150, 0),)),
}
# the measured series of each trend whose smallest and largest value per window are drawn too
# (thin, translucent: the band the ball-pass ripple spans); the setpoints and the regime counts
# have none
TREND_BANDS: dict[str, tuple[int, ...]] = {
    "friction_torque_n_m": (0,),
    "loads_n": (0,),
    "speeds_rad_s": (1, 2),
    "min_lambda": (0, 1),
    "temperatures_c": (1,),
    "electrical/capacitance_pf": (0,),
    "electrical/resistance_log10_kohm": (0, 1),
    "electrical/shaft_voltage_v": (0,),
    "electrical/shaft_current_ma": (0,),
    "electrical/film_field_v_per_um": (0,),
    "electrical/current_density_a_per_mm2": (0,),
}
BAND_ALPHA = 110
TREND_WIDTH = 1.5  # [ui points] the window means
BAND_WIDTH = 0.75  # [ui points] their min / max
CAPACITANCE_LEAF = "electrical/capacitance_pf"
OFF_SCALE_LEAF = f"{CAPACITANCE_LEAF}/off_scale"  # marker: a capacitance off the robust scale
FILM_BROKEN_LEAF = f"{CAPACITANCE_LEAF}/film_broken"  # marker: no capacitance (metal contact)
# markers beside every trend where a setpoint or the defects changed (`{trend}/changes`)
CHANGE_MARKER: dict[str, Any] = dict(
    names=["setpoint / defect change"], colors=[(40, 40, 40)], markers=["Diamond"], marker_sizes=[5.0]
)
FAST_SERIES = tuple(SERIES)


def ball_rgb(i: int, count: int, side: int) -> tuple[int, int, int]:
    r, g, b = colorsys.hsv_to_rgb(i / max(count, 1), 0.75 if side == 0 else 0.55, 0.95 if side == 0 else 0.7)
    return int(r * 255), int(g * 255), int(b * 255)


def _circle(radius_m: float, n: int = 181) -> np.ndarray:
    a = np.linspace(0.0, 2.0 * math.pi, n)
    return np.column_stack([radius_m * np.cos(a), radius_m * np.sin(a), np.zeros(n)])


@dataclass
class TwinLayout:
    """What the recorder knows of one twin (geometry optional) and its entity paths."""

    bearing_id: str
    designation: str
    ball_count: int
    pitch_radius_m: float | None = None
    ball_radius_m: float | None = None
    inner_raceway_radius_m: float | None = None
    outer_raceway_radius_m: float | None = None
    load_scale_m_per_n: float | None = None
    vibration: bool = False  # the twin has the housing and accelerometer
    # state of the event rows, per output segment (reset when a segment starts)
    last: dict = field(default_factory=dict)

    @property
    def has_geometry(self) -> bool:
        return self.pitch_radius_m is not None

    @property
    def root(self) -> str:
        return f"bearing/{self.bearing_id}"

    def path(self, leaf: str) -> str:
        return f"{self.root}/{leaf}"

    @property
    def bar_width_deg(self) -> float:
        return 360.0 / max(self.ball_count, 1) * 0.3


def trend_style(leaf: str, names: tuple[str, ...], colors: tuple) -> rr.SeriesLines:
    """Series names, colours and widths of a trend: the window means, then the min and the max
    of the series in `TREND_BANDS` (both named "... min-max", thin and translucent)."""
    band = TREND_BANDS.get(leaf, ())
    # min and max share a name: the plot legend shows one entry for both (and toggles both)
    lo = [f"{names[i].split(' [')[0]} min-max" if len(names) > 1 else "min-max" for i in band]
    hi = lo
    faded = [(*colors[i], BAND_ALPHA) for i in band]
    return rr.SeriesLines(
        names=[*names, *lo, *hi],
        colors=[(*c, 255) for c in colors] + faded + faded,
        widths=[TREND_WIDTH] * len(names) + [BAND_WIDTH] * (2 * len(band)),
    )


def send_static(stream: rr.RecordingStream, tw: TwinLayout) -> None:
    """The static data of one twin: geometry, legends, series names and colours."""
    root = tw.root
    s = stream
    s.log(
        root,
        rr.AnnotationContext([(c, REGIME_LABEL[c], tuple(int(v) for v in REGIME_RGB[c])) for c in range(4)]),
        static=True,
    )
    rb, pitch = tw.ball_radius_m, tw.pitch_radius_m
    inner, outer = tw.inner_raceway_radius_m, tw.outer_raceway_radius_m
    if rb is not None and pitch is not None and inner is not None and outer is not None:  # tw.has_geometry
        line = rr.components.Radius.ui_points(1.5)
        s.log(
            f"{root}/geometry/inner_raceway",
            rr.LineStrips3D([_circle(inner)], radii=line, colors=_RACEWAY_RGB),
            static=True,
        )
        s.log(
            f"{root}/geometry/outer_raceway",
            rr.LineStrips3D([_circle(outer)], radii=line, colors=_RACEWAY_RGB),
            static=True,
        )
        s.log(
            f"{root}/geometry/pitch_circle",
            rr.LineStrips3D([_circle(pitch)], radii=rr.components.Radius.ui_points(0.5), colors=_PITCH_RGB),
            static=True,
        )
        s.log(
            f"{root}/geometry/load_line",
            rr.Arrows3D(
                origins=[[outer * 1.05, 0.0, 0.0]],
                vectors=[[outer * 0.35, 0.0, 0.0]],
                colors=[(230, 60, 60)],
                labels=["Fr"],
                radii=rr.components.Radius.ui_points(2.0),
            ),
            static=True,
        )
        s.log(f"{root}/balls", rr.Points3D.from_fields(radii=[rb], show_labels=False), static=True)
        s.log(f"{root}/loads", rr.Arrows3D.from_fields(colors=[INNER_RGB], radii=[0.08 * rb]), static=True)
    for field_, _title in LOAD_ZONE:
        for side, name in enumerate(SIDES):
            s.log(
                f"{root}/load_zone/{field_}/{name}",
                [
                    rr.components.ColorBatch([INNER_RGB if side == 0 else OUTER_RGB]).described(
                        rr.BarChart.descriptor_color()
                    ),
                    rr.components.LengthBatch(np.full(tw.ball_count, tw.bar_width_deg, dtype=np.float32)).described(
                        rr.BarChart.descriptor_widths()
                    ),
                ],
                static=True,
            )
    for leaf, (names, colors) in SERIES.items():
        s.log(f"{root}/{leaf}", trend_style(leaf, names, colors), static=True)
        s.log(f"{root}/{leaf}/changes", rr.SeriesPoints(**CHANGE_MARKER), static=True)
    s.log(
        f"{root}/{OFF_SCALE_LEAF}",
        rr.SeriesPoints(
            names=["off scale (value in events)"], colors=[(220, 40, 40)], markers=["Up"], marker_sizes=[5.0]
        ),
        static=True,
    )
    s.log(
        f"{root}/{FILM_BROKEN_LEAF}",
        rr.SeriesPoints(
            names=["film broken: C undefined"], colors=[(220, 40, 40)], markers=["Cross"], marker_sizes=[5.0]
        ),
        static=True,
    )
    z = tw.ball_count
    contact_names = [f"ball {i} {side}" for i in range(z) for side in SIDES]
    contact_colors = [ball_rgb(i, z, k) for i in range(z) for k in range(2)]
    for leaf, _title in CONTACT_SERIES:
        s.log(f"{root}/contacts/{leaf}", rr.SeriesLines(names=contact_names, colors=contact_colors), static=True)
    s.log(
        f"{root}/electrical/discharge_risk",
        rr.StateConfiguration(
            values=list(RISK_VALUES),
            labels=["no discharge risk", "discharge possible", "discharge likely"],
            colors=np.array(RISK_RGBA, dtype=np.uint32),
        ),
        static=True,
    )
    if tw.vibration:
        for leaf, (names, colors) in VIBRATION_SERIES.items():
            # a waveform drawn at min-max per pixel keeps its peaks (an average per pixel halves them)
            policy: Literal["MinMax"] | None = "MinMax" if leaf == WAVEFORM_LEAF else None
            s.log(
                f"{root}/{leaf}",
                rr.SeriesLines(names=list(names), colors=list(colors), aggregation_policy=policy),
                static=True,
            )
        for leaf, rgb in (("peaks", (80, 160, 255)), ("defect_lines", (230, 60, 60))):
            s.log(
                f"{root}/vibration/envelope/{leaf}",
                [
                    rr.components.ColorBatch([rgb]).described(rr.BarChart.descriptor_color()),
                    rr.components.LengthBatch(np.full(len(VIB_LINES), ENVELOPE_BAR_HZ, dtype=np.float32)).described(
                        rr.BarChart.descriptor_widths()
                    ),
                ],
                static=True,
            )
        for leaf in ("vibration/envelope/spectrum", "vibration/spectrum"):
            s.log(
                f"{root}/{leaf}",
                [rr.components.ColorBatch([SPECTRUM_RGB]).described(rr.BarChart.descriptor_color())],
                static=True,
            )
        for name, rgb in zip(CURSOR_NAMES, VIB_LINE_RGB, strict=True):
            s.log(
                f"{root}/vibration/envelope/cursor/{name}",
                [rr.components.ColorBatch([(*rgb, CURSOR_ALPHA)]).described(rr.BarChart.descriptor_color())],
                static=True,
            )
        s.log(
            f"{root}/vibration/spectrum_envelope_band",
            [rr.components.ColorBatch([ENVELOPE_BAND_RGBA]).described(rr.BarChart.descriptor_color())],
            static=True,
        )
    for alarm_id in ALARM_IDS:
        s.log(
            f"{root}/alarm_states/{alarm_id}",
            rr.StateConfiguration(
                values=list(ALARM_STATES),
                labels=[f"{alarm_id} {v}" for v in ALARM_STATES],
                colors=np.array(ALARM_STATE_RGBA, dtype=np.uint32),
            ),
            static=True,
        )
