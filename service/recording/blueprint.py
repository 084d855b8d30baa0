"""The default blueprint of a recording: one twin's views (`twin_blueprint`: the bearing in 3D, the
load zone, the trends, the events, the alarms, the electrical and vibration panels), and the
whole layout with one tab per twin (`blueprint`). The entities it shows: service.recording.layout.
"""

from __future__ import annotations

import rerun.blueprint as rrb
from rerun.encodings import TimeRange

from service.recording.layout import LOAD_ZONE, SEQ, SERIES, SIM_TIME, VIBRATION_SERIES, WAVEFORM_LEAF, TwinLayout


def _window(seconds: float | None):
    """The span a trend view shows: the last `seconds` before the time cursor, or (None) the
    whole recording whatever the cursor."""
    if not seconds:
        return rrb.VisibleTimeRange(
            SIM_TIME, start=rrb.TimeRangeBoundary.infinite(), end=rrb.TimeRangeBoundary.infinite()
        )
    return rrb.VisibleTimeRange(
        SIM_TIME,
        start=rrb.TimeRangeBoundary.cursor_relative(seconds=-float(seconds)),
        end=rrb.TimeRangeBoundary.cursor_relative(),
    )


def twin_blueprint(tw: TwinLayout, series_window_s: float | None, live: bool = True) -> rrb.Container:
    """The default layout of one twin: top, the bearing in 3D, the load zone now and the
    bearing-level trends with the setpoint beside them; bottom, the events, the alarms (states
    and events) and the electrical panel. The per-contact series (`contacts/...`) are not in it (add them from the
    streams)."""
    root = f"/{tw.root}"
    tag = tw.bearing_id
    window = _window(series_window_s)
    # the x axis shows the whole recording too (else the viewer opens it on a span at the cursor)
    axis_x = (
        rrb.TimeAxis(view_range=TimeRange(start=rrb.TimeRangeBoundary.infinite(), end=rrb.TimeRangeBoundary.infinite()))
        if not series_window_s
        else None
    )

    def ts(title: str, leaf: str, legend: bool | None = None) -> rrb.TimeSeriesView:
        # a key where a view has several quantities; one quantity: its title names it and its unit
        if legend is None:
            legend = len(SERIES.get(leaf, VIBRATION_SERIES.get(leaf, ((), ())))[0]) > 1
        # the trend, its change markers (and for the capacitance its off-scale markers)
        return rrb.TimeSeriesView(
            name=title,
            origin=root,
            contents=[f"+ {root}/{leaf}/**"],
            time_ranges=window,
            axis_x=axis_x,
            plot_legend=rrb.PlotLegend(visible=legend, corner="LeftTop"),
        )

    def bars(field_: str, title: str) -> rrb.BarChartView:
        return rrb.BarChartView(
            name=f"{title} vs azimuth [deg]: inner blue, outer violet",
            origin=root,
            contents=[f"+ {root}/load_zone/{field_}/**"],
            plot_legend=rrb.PlotLegend(visible=False),
        )

    top: list = []
    shares: list = []
    outer = tw.outer_raceway_radius_m
    if outer is not None:  # tw.has_geometry
        distance = 3.4 * outer
        top.append(
            rrb.Spatial3DView(
                name=f"{tag} ({tw.designation}): balls by regime (colours as in 'balls per regime')",
                origin=root,
                contents=[f"+ {root}/geometry/**", f"+ {root}/balls", f"+ {root}/loads"],
                # look along the axis (-z) with the radial load line (+x, azimuth 0) pointing down
                eye_controls=rrb.EyeControls3D(
                    position=[0.0, 0.0, distance], look_target=[0.0, 0.0, 0.0], eye_up=[-1.0, 0.0, 0.0]
                ),
                line_grid=False,
            )
        )
        shares.append(1.0)
    top.append(rrb.Vertical(*(bars(f, t) for f, t in LOAD_ZONE), name="load zone now (inner blue, outer violet)"))
    shares.append(1.0)
    top.append(
        rrb.Grid(
            ts("loads [N]", "loads_n"),
            ts("speeds [rad/s]", "speeds_rad_s"),
            ts("friction torque [N m]", "friction_torque_n_m"),
            ts("min Lambda [-]", "min_lambda"),
            ts("balls per regime (mean)", "regime_counts"),
            ts("temperatures [degC]", "temperatures_c"),
            ts("thermal network [degC]", "thermal/nodes_c"),
            ts("friction heat by source [W]", "thermal/heat_w"),
            grid_columns=3,
            name="trends",
        )
    )
    shares.append(2.4)
    electrical = rrb.Vertical(
        rrb.Grid(
            ts("capacitance [pF]", "electrical/capacitance_pf"),
            ts("log10 R, |Z| [kohm]", "electrical/resistance_log10_kohm"),
            ts("film field [V/um]", "electrical/film_field_v_per_um"),
            ts("shaft voltage [V]", "electrical/shaft_voltage_v"),
            ts("shaft current [mA]", "electrical/shaft_current_ma"),
            ts("current density [A/mm2]", "electrical/current_density_a_per_mm2"),
            grid_columns=3,
        ),
        rrb.StateTimelineView(
            name="discharge risk", origin=root, contents=[f"+ {root}/electrical/discharge_risk"], time_ranges=window
        ),
        row_shares=[4.0, 1.0],
        name="electrical",
    )
    events = rrb.TextLogView(
        name=f"{tag}: events (setpoints, scenarios, restarts, fallbacks)",
        origin=root,
        contents=[f"+ {root}/events"],
        columns=rrb.archetypes.TextLogColumns(
            timeline_columns=[rrb.encodings.TimelineColumn(SIM_TIME), rrb.encodings.TimelineColumn(SEQ, visible=False)],
            text_log_columns=[
                rrb.encodings.TextLogColumn("LogLevel"),
                rrb.encodings.TextLogColumn("Body"),
                rrb.encodings.TextLogColumn("EntityPath", visible=False),
            ],
        ),
    )
    alarms = rrb.Vertical(
        rrb.StateTimelineView(
            name=f"{tag}: alarm states", origin=root, contents=[f"+ {root}/alarm_states/**"], time_ranges=window
        ),
        rrb.TextLogView(
            name=f"{tag}: alarm events",
            origin=root,
            contents=[f"+ {root}/alarms/**"],
            columns=rrb.archetypes.TextLogColumns(
                timeline_columns=[
                    rrb.encodings.TimelineColumn(SIM_TIME),
                    rrb.encodings.TimelineColumn(SEQ, visible=False),
                ],
                text_log_columns=[
                    rrb.encodings.TextLogColumn("LogLevel"),
                    rrb.encodings.TextLogColumn("Body"),
                    rrb.encodings.TextLogColumn("EntityPath", visible=False),
                ],
            ),
        ),
        row_shares=[1.0, 1.0],
        name="alarms",
    )
    rows = [
        rrb.Horizontal(*top, column_shares=shares),
        rrb.Horizontal(events, alarms, electrical, column_shares=[1.0, 1.0, 1.6]),
    ]
    if tw.vibration:
        rows.append(
            rrb.Horizontal(
                rrb.Vertical(
                    # live: the last 0.1 s at full rate; a file keeps bursts (service.recording.archive):
                    # the whole run, each burst drawn min-max
                    rrb.TimeSeriesView(
                        name="housing acceleration [m/s^2] " + ("(last 0.1 s)" if live else "(bursts)"),
                        origin=root,
                        contents=[f"+ {root}/{WAVEFORM_LEAF}"],
                        time_ranges=_window(0.1 if live else None),
                        plot_legend=rrb.PlotLegend(visible=False),
                    ),
                    rrb.BarChartView(
                        name="acceleration spectrum [m/s^2] vs [Hz]; envelope band orange",
                        origin=root,
                        contents=[f"+ {root}/vibration/spectrum", f"+ {root}/vibration/spectrum_envelope_band"],
                        plot_legend=rrb.PlotLegend(visible=False),
                    ),
                ),
                # no legend: it would show the cursors' full entity paths over the spectrum
                rrb.BarChartView(
                    name="envelope spectrum [m/s^2] vs [Hz]; 1-3x BPFO red, BPFI blue, 2xBSF orange, "
                    "BSF green, FTF grey",
                    origin=root,
                    contents=[f"+ {root}/vibration/envelope/spectrum", f"+ {root}/vibration/envelope/cursor/**"],
                    plot_legend=rrb.PlotLegend(visible=False),
                ),
                rrb.Grid(
                    ts("RMS, peak [m/s^2]", "vibration/acceleration_rms_peak_m_s2"),
                    ts("velocity RMS [mm/s]", "vibration/velocity_rms_mm_s"),
                    ts("kurtosis, crest [-]", "vibration/kurtosis"),
                    ts("envelope lines [m/s^2]", "vibration/envelope_lines_m_s2"),
                    grid_columns=2,
                ),
                column_shares=[1.1, 1.9, 1.0],
                name="vibration",
            )
        )
    return rrb.Vertical(*rows, row_shares=[1.5, 1.0, 1.3][: len(rows)], name=tag)


def blueprint(twins: list[TwinLayout], series_window_s: float | None, live: bool = False) -> rrb.Blueprint:
    """The default layout: one twin, or one tab per twin. `series_window_s` [s]: the span of the
    trend views (None: the whole recording). `live`: the time cursor follows the newest data (a
    viewer watching the twins); else (a file) it stays where the viewer opens the recording."""
    layouts = [twin_blueprint(tw, series_window_s, live) for tw in twins]
    body: rrb.Container
    if not layouts:
        body = rrb.Vertical()
    elif len(layouts) == 1:
        body = layouts[0]
    else:
        body = rrb.Tabs(*layouts)
    return rrb.Blueprint(
        body,
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(timeline=SIM_TIME, play_state="following" if live else "paused", state="collapsed"),
        collapse_panels=True,
    )
