"""Scenarios: YAML timelines of setpoints and ramps, validated with pydantic.

Format (schema "bearing-twin/scenario/1"; all times are SIMULATED seconds from the scenario start)::

    name: seed000_startup_steady_slowdown    # required, [A-Za-z0-9_.-]
    description: free text                   # optional
    bearing: "6208"                          # catalog designation (default 6208), or a bearing
                                             #   spec: a mapping of twin.spec.BearingSpec fields, or
                                             #   (scenario files only) a .yaml/.yml/.json spec file,
                                             #   relative to the scenario file
    diametral_clearance_m: 0.0               # mounting [m], negative = preload (default 0)
    lubricant: seed-000                      # 'seed-000' or 'ISO VG n' (default seed-000)
    thermal: {shear_heating: true}           # electro-thermal options (twin.spec.Thermal; optional)
    initial:                                 # setpoint at t = 0 (partial; unset fields keep
      shaft_speed_rad_s: 0.0                 #   the twin's value, or the defaults for a fresh twin)
      radial_load_n: 3000.0
    duration_s: 0.4                          # length of the scenario [s]
    sample_every_s: 0.001                    # table / recording sample period [s] (scenario run)
    steps:                                   # in order of at_s
      - at_s: 0.0                            # when the step starts [s]
        phase: start-up                      # optional label, copied into the table
        ramp: {shaft_speed_rad_s: 500.0}     # linear ramp from the value in force at at_s ...
        over_s: 0.1                          # ... to the target over this many seconds
      - at_s: 0.25
        set: {radial_load_n: 5000.0}         # a step change (partial setpoint)
    runs:                                    # optional: several runs of the same timeline,
      - id: pd_minus_12_6um                  #   each with its own mounting / bearing / lubricant /
        label: "Pd = -12.6 um"               #   thermal / initial / steps / duration_s
        diametral_clearance_m: -12.6e-6

Rules:

* every step has one of `set` or `ramp`, or `defects` (the local defects in force from `at_s`,
  a list in the vocabulary of twin.vibration.defects, `[]` clears them; with `set` or
  `ramp` beside it, or alone; checked against the bearing's geometry like the setpoint values
  against its limits); a ramp needs `over_s` > 0 and must end by `duration_s`; `at_s` is
  non-decreasing and below `duration_s`;
* setpoint fields are those of `twin.setpoint.SetpointUpdate` (units in the names); an unknown
  field is an error, and so is a value that is not a number (a bool, a quoted "3000");
* `bearing: 6208` (a YAML integer) is the designation "6208";
* `bearing:` as a mapping is a whole bearing spec (twin.spec.BearingSpec: geometry [m], material,
  lubricant, mounting, housing, surface_profile, ...), validated as the catalog's, errors named
  `bearing.geometry.ball_count` and so on; `diametral_clearance_m`, `lubricant` and `thermal`
  written beside it replace the spec's own. A spec file path is read by `load_scenario` (a
  scenario file: `scenario run`, `scenario check`, the service's named scenarios) relative to the
  scenario file; an inline scenario posted over HTTP gives the spec as a mapping (the service
  never reads a file a request names);
* values are checked against the bearing's limits before anything runs (`check_limits`, by
  `scenario check` as by `scenario run` and the service), so an out-of-range step is refused
  with its position, field and the bearing's own range;
* the engine's own shaft acceleration limit (ModelOptions.speed_ramp_rad_s2, 5000 rad/s^2 by
  default) still applies: a speed ramp faster than that lags behind its setpoint.

A twin in a service runs one run of a scenario at a time (`POST /v1/bearings/{id}/scenario`): the
runs must not change the twin's bearing, mounting, lubricant or thermal options (those are fixed
when a twin is created); `bearing-twin scenario run FILE` creates a fresh twin for every run.
Reading and validating a scenario (`load_scenario`, `scenario_from_dict`): service.core.scenario_files.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Discriminator, Field, Tag, field_validator, model_validator

from service.core.measured_temperature import MeasuredTemperature
from service.keys import TWIN_ID_PATTERN
from twin import catalog
from twin.setpoint import Setpoint, SetpointLimits, SetpointUpdate
from twin.spec import BearingSpec, Clearance, Thermal

_NAME_RE = TWIN_ID_PATTERN  # a scenario or run name names the twin of an offline run
_FROZEN = ConfigDict(frozen=True, extra="forbid", strict=True, allow_inf_nan=False)


DESIGNATION_TAG, SPEC_TAG = "designation-text", "inline-spec"  # union tags, dropped from error paths


def _bearing_kind(value: Any) -> str:
    return SPEC_TAG if isinstance(value, (dict, BearingSpec)) else DESIGNATION_TAG


Bearing = Annotated[
    Annotated[str, Tag(DESIGNATION_TAG), Field(max_length=32)] | Annotated[BearingSpec, Tag(SPEC_TAG)],
    Discriminator(_bearing_kind),
    Field(
        description="Catalog designation [text], or a whole bearing spec (twin.spec.BearingSpec, fields with units) "
        "[object]."
    ),
]
"""A scenario's bearing: a catalog designation or an inline BearingSpec."""


class ScenarioError(ValueError):
    """A scenario that cannot run here; `field` names where (e.g. 'steps[2].ramp.radial_load_n')."""

    def __init__(self, field: str, message: str, allowed: list | None = None):
        self.field, self.message, self.allowed = field, message, allowed
        # the message may already start with the field (several errors, each with its path)
        super().__init__(message if message.startswith(f"{field}: ") else f"{field}: {message}")


class ScenarioStep(BaseModel):
    """One timed change of the setpoint."""

    model_config = _FROZEN
    at_s: float = Field(ge=0.0, description="Start of the step, from the scenario start [s of simulated time].")
    set: SetpointUpdate | None = Field(
        default=None, description="Step change: partial setpoint applied at at_s (fields with units)."
    )
    ramp: SetpointUpdate | None = Field(
        default=None,
        description="Ramp targets: partial setpoint reached linearly at at_s + over_s (fields with units).",
    )
    over_s: float | None = Field(
        default=None, gt=0.0, description="Ramp duration [s of simulated time]; only with ramp."
    )
    phase: str | None = Field(
        default=None, max_length=64, description="Optional label of the phase this step starts [text]."
    )
    defects: list[dict[str, Any]] | None = Field(
        default=None,
        max_length=64,
        description="Local defects in force from at_s (twin.vibration.defects vocabulary: kind outer | "
        "inner | ball, width_m, length_m, depth_m [m], ...; [] clears them), checked against the bearing's "
        "geometry before the run starts.",
    )
    temperature: MeasuredTemperature | None = Field(
        default=None,
        description="A measured temperature at at_s for the thermal network to follow (the twin's "
        "setpoint oil_temperature_c is the ambient; needs ModelOptions.thermal = 'network').",
    )

    @model_validator(mode="after")
    def _one_action(self) -> ScenarioStep:
        if self.set is not None and self.ramp is not None:
            raise ValueError("a step has one of 'set' or 'ramp', not both")
        if self.set is None and self.ramp is None and self.defects is None and self.temperature is None:
            raise ValueError("a step needs one of 'set' or 'ramp', or 'defects', or 'temperature'")
        if self.ramp is not None and self.over_s is None:
            raise ValueError("a ramp needs over_s > 0 [s]")
        if self.set is not None and self.over_s is not None:
            raise ValueError("over_s [s] belongs to a ramp, not to a set")
        return self

    @property
    def end_s(self) -> float:
        """When the step's change is complete [s]."""
        return self.at_s + (self.over_s or 0.0)


class ScenarioRun(BaseModel):
    """One run of a multi-run scenario: overrides of the scenario's top-level fields."""

    model_config = _FROZEN
    id: str | None = Field(default=None, pattern=_NAME_RE, description="Run name [text]; default run<i>.")
    label: str | None = Field(default=None, max_length=128, description="Human label of the run [text].")
    bearing: Bearing | None = None
    diametral_clearance_m: Clearance | None = None
    lubricant: str | None = Field(
        default=None, max_length=64, description="Lubricant: 'seed-000' or 'ISO VG n' [text]."
    )
    thermal: Thermal | None = Field(
        default=None,
        description="Electro-thermal options replacing the scenario's (twin.spec.Thermal, units in each field).",
    )
    initial: SetpointUpdate | None = Field(
        default=None, description="Initial setpoint, merged over the scenario's (fields with units)."
    )
    steps: list[ScenarioStep] | None = Field(default=None, description="Steps replacing the scenario's.")
    duration_s: float | None = Field(default=None, gt=0.0, le=3600.0, description="Run length [s of simulated time].")

    @field_validator("bearing", mode="before")
    @classmethod
    def _designation_text(cls, value: Any) -> Any:
        return _designation_text(value)


def _drop_empty_steps(steps: list[ScenarioStep]) -> list[ScenarioStep]:
    return [s for s in steps if s.defects is not None or s.temperature is not None or _sets_fields(s)]


def _sets_fields(step: ScenarioStep) -> bool:
    """Whether the step's setpoint update (set or ramp) names a field."""
    update = step.set or step.ramp
    return update is not None and bool(update.model_dump(exclude_none=True))


def _check_steps(steps: list[ScenarioStep], duration_s: float, where: str) -> None:
    """Model-level checks; messages start with the field path ('steps[2].at_s: ...')."""
    previous = 0.0
    for i, step in enumerate(steps):
        if step.at_s < previous:
            raise ValueError(
                f"{where}[{i}].at_s: {step.at_s:g} s is before the previous step "
                f"({previous:g} s); steps must be in order of at_s"
            )
        previous = step.at_s
        if step.at_s >= duration_s and step.at_s > 0.0:
            raise ValueError(f"{where}[{i}].at_s: {step.at_s:g} s must be below duration_s = {duration_s:g} s")
        if step.end_s > duration_s + 1e-12:
            raise ValueError(
                f"{where}[{i}].over_s: the ramp ends at {step.end_s:g} s, after duration_s = {duration_s:g} s"
            )


class Scenario(BaseModel):
    """A timeline of setpoints and ramps (see the module docstring for the YAML format)."""

    model_config = _FROZEN

    name: str = Field(pattern=_NAME_RE, description="Scenario name [text: letters, digits, _ . -].")
    description: str = Field(default="", max_length=4000, description="What the scenario shows [text].")
    bearing: Bearing = catalog.DEFAULT_DESIGNATION
    diametral_clearance_m: Clearance = 0.0
    lubricant: str = Field(default="seed-000", max_length=64, description="Lubricant: 'seed-000' or 'ISO VG n' [text].")
    thermal: Thermal | None = Field(
        default=None,
        description="Electro-thermal options of the bearing (twin.spec.Thermal: shear / current heating, R_b, H_c; "
        "units in each field); default: the spec's.",
    )
    initial: SetpointUpdate = Field(
        default_factory=SetpointUpdate, description="Setpoint applied at t = 0 (fields with units)."
    )
    duration_s: float = Field(gt=0.0, le=3600.0, description="Scenario length [s of simulated time].")
    sample_every_s: float = Field(
        default=0.001, ge=1e-5, le=10.0, description="Sample period of the table and recording [s of simulated time]."
    )
    steps: list[ScenarioStep] = Field(default_factory=list, description="Timed setpoints and ramps, in order of at_s.")
    runs: list[ScenarioRun] | None = Field(
        default=None,
        min_length=1,
        max_length=100,
        description="Optional runs with other mountings / bearings / timelines.",
    )
    warnings: list[str] = Field(default_factory=list, description="Notes of the loader on what it did not take [text].")

    @field_validator("bearing", mode="before")
    @classmethod
    def _designation_text(cls, value: Any) -> Any:
        return _designation_text(value)

    @field_validator("bearing")
    @classmethod
    def _known_bearing(cls, value: str | BearingSpec) -> str | BearingSpec:
        return _check_designation(value) if isinstance(value, str) else value

    @field_validator("lubricant")
    @classmethod
    def _known_lubricant(cls, value: str) -> str:
        return _check_lubricant(value)

    @model_validator(mode="after")
    def _timeline(self) -> Scenario:
        _check_steps(self.steps, self.duration_s, "steps")
        for j, run in enumerate(self.runs or []):
            if isinstance(run.bearing, str):
                try:
                    _check_designation(run.bearing)
                except ValueError as exc:
                    raise ValueError(f"runs[{j}].bearing: {exc}") from None
            if run.lubricant is not None:
                _check_lubricant(run.lubricant)
            steps = run.steps if run.steps is not None else self.steps
            _check_steps(
                steps, run.duration_s or self.duration_s, f"runs[{j}].steps" if run.steps is not None else "steps"
            )
        ids = [r.id for r in self.resolved_runs()]
        if len(set(ids)) != len(ids):
            raise ValueError(f"runs: run ids must be unique, got {ids}")
        return self

    # ---- resolution -------------------------------------------------------------------------
    def resolved_runs(self) -> list[ResolvedRun]:
        """Every run with the top-level defaults filled in (one run when `runs` is absent)."""
        top = frozenset(self.model_fields_set & {"bearing", "diametral_clearance_m", "lubricant"})
        if not self.runs:
            return [
                ResolvedRun(
                    scenario=self.name,
                    index=0,
                    id="run0",
                    label=self.name,
                    bearing=self.bearing,
                    diametral_clearance_m=self.diametral_clearance_m,
                    lubricant=self.lubricant,
                    initial=self.initial,
                    thermal=self.thermal,
                    steps=_drop_empty_steps(self.steps),
                    duration_s=self.duration_s,
                    sample_every_s=self.sample_every_s,
                    explicit=top,
                )
            ]
        out = []
        for j, run in enumerate(self.runs):
            initial = self.initial
            if run.initial is not None:
                initial = SetpointUpdate(
                    **{**self.initial.model_dump(exclude_none=True), **run.initial.model_dump(exclude_none=True)}
                )
            out.append(
                ResolvedRun(
                    scenario=self.name,
                    index=j,
                    id=run.id or f"run{j}",
                    label=run.label or run.id or f"run{j}",
                    bearing=run.bearing or self.bearing,
                    diametral_clearance_m=(
                        self.diametral_clearance_m if run.diametral_clearance_m is None else run.diametral_clearance_m
                    ),
                    lubricant=run.lubricant or self.lubricant,
                    initial=initial,
                    thermal=run.thermal if run.thermal is not None else self.thermal,
                    steps=_drop_empty_steps(run.steps if run.steps is not None else self.steps),
                    duration_s=run.duration_s or self.duration_s,
                    sample_every_s=self.sample_every_s,
                    explicit=top
                    | frozenset(
                        k for k in ("bearing", "diametral_clearance_m", "lubricant") if getattr(run, k) is not None
                    ),
                )
            )
        return out

    def check_bearing_limits(self) -> None:
        """Check every run's values against its bearing's own limits (ScenarioError naming the
        run, step and field): the check `scenario run` and the service make before running."""
        runs = self.resolved_runs()
        for run in runs:
            where = f"runs[{run.index}]." if len(runs) > 1 else ""
            run.check_limits(run.bearing_limits(), where=where)
            run.check_defects(run.spec().geometry, where=where)

    @property
    def total_duration_s(self) -> float:
        """Simulated seconds of all runs together [s]."""
        return sum(r.duration_s for r in self.resolved_runs())


def _designation_text(value: Any) -> Any:
    """YAML reads `bearing: 6208` as a number: a designation written as an integer is taken as
    its text ("6208"); booleans and other types are left to the validation (refused)."""
    if isinstance(value, int) and not isinstance(value, bool):
        return str(value)
    return value


def _check_designation(value: str) -> str:
    if value.strip().lower().endswith(catalog.SPEC_FILE_SUFFIXES):
        raise ValueError(
            f"{value!r} is a bearing spec file: only a scenario file names one (bearing-twin scenario "
            "run FILE, a named scenario of the service); an inline scenario gives the spec as a mapping "
            "of BearingSpec fields (geometry, material, lubricant, ...)"
        )
    known = catalog.designations()
    if value.strip().upper() not in known:
        raise ValueError(f"unknown bearing {value!r}; known: {', '.join(known)}")
    return value.strip().upper()


def _check_lubricant(value: str) -> str:
    try:
        catalog.lubricant(value)
    except ValueError as exc:
        raise ValueError(str(exc).removeprefix("lubricant: ")) from None
    return value


@dataclass(frozen=True)
class ResolvedRun:
    """One run with every field decided: what a runner executes."""

    scenario: str
    index: int
    id: str
    label: str
    bearing: str | BearingSpec  # catalog designation or a whole spec
    diametral_clearance_m: float
    lubricant: str
    initial: SetpointUpdate
    steps: list[ScenarioStep]
    duration_s: float
    sample_every_s: float
    explicit: frozenset[str] = frozenset()  # which of bearing / clearance / lubricant were written
    thermal: Thermal | None = None  # electro-thermal options (None: the spec's defaults)

    @property
    def designation(self) -> str:
        """The bearing's designation (the spec's with a spec)."""
        return self.bearing if isinstance(self.bearing, str) else self.bearing.designation

    def check_twin(
        self,
        designation: str,
        diametral_clearance_m: float,
        lubricant: str,
        thermal: Thermal | None = None,
        spec: BearingSpec | None = None,
    ) -> None:
        """Raise ScenarioError if the run asks for another bearing, mounting, lubricant or
        electro-thermal options than a running twin has (those are fixed when a twin is created).
        A run with a bearing spec needs the twin's whole `spec` to be the same."""
        if isinstance(self.bearing, BearingSpec):
            if spec is None or self.spec() != spec:
                raise ScenarioError(
                    "bearing",
                    f"run {self.id!r} of scenario {self.scenario!r} needs the bearing spec "
                    f"{self.bearing.designation!r} it gives, this twin has another bearing ({designation!r}): "
                    "create a twin with that spec (POST /v1/bearings with 'spec') or run the scenario offline "
                    "(bearing-twin scenario run)",
                    [self.bearing.designation],
                )
            return
        wanted: dict[str, tuple[Any, Any]] = {
            "bearing": (self.bearing, designation),
            "diametral_clearance_m": (self.diametral_clearance_m, diametral_clearance_m),
            "lubricant": (catalog.lubricant(self.lubricant).name, lubricant),
        }
        for name in ("bearing", "diametral_clearance_m", "lubricant"):
            if name not in self.explicit:
                continue
            want, have = wanted[name]
            same = abs(want - have) <= 1e-12 if isinstance(want, float) else str(want) == str(have)
            if not same:
                raise ScenarioError(
                    name,
                    f"run {self.id!r} of scenario {self.scenario!r} needs {name} = {want!r}, "
                    f"this twin has {have!r}: create a twin with it (POST /v1/bearings) or run the "
                    f"scenario offline (bearing-twin scenario run)",
                    [want],
                )
        if self.thermal is not None and thermal is not None and self.thermal != thermal:
            raise ScenarioError(
                "thermal",
                f"run {self.id!r} of scenario {self.scenario!r} needs thermal = "
                f"{self.thermal.model_dump()}, this twin has {thermal.model_dump()}: create a twin with it "
                f"(POST /v1/bearings with 'thermal') or run the scenario offline (bearing-twin scenario run)",
                [self.thermal.model_dump()],
            )

    def spec(self) -> BearingSpec:
        """The bearing this run asks for: designation, mounting, lubricant, thermal options (with a
        spec: the spec, with the clearance, lubricant and thermal options written beside it)."""
        if isinstance(self.bearing, BearingSpec):
            update: dict[str, Any] = {}
            if "diametral_clearance_m" in self.explicit:
                update["mounting"] = self.bearing.mounting.model_copy(
                    update={"diametral_clearance_m": self.diametral_clearance_m}
                )
            if "lubricant" in self.explicit:
                update["lubricant"] = catalog.lubricant(self.lubricant)
            if self.thermal is not None:
                update["thermal"] = self.thermal
            return self.bearing.model_copy(update=update) if update else self.bearing
        return catalog.bearing(
            self.bearing,
            diametral_clearance_m=self.diametral_clearance_m,
            lubricant=catalog.lubricant(self.lubricant),
            **({"thermal": self.thermal} if self.thermal else {}),
        )

    def bearing_limits(self) -> SetpointLimits:
        """The setpoint limits of this run's bearing (its compiled model)."""
        from twin.model import make_model

        return SetpointLimits.for_model(make_model(self.spec()))

    def initial_setpoint(self, base: Setpoint | None = None) -> Setpoint:
        """The complete setpoint at t = 0 (initial merged over `base` or the defaults)."""
        return self.initial.apply_to(base or Setpoint())

    def iter_values(self):
        """(where, field, value) of every setpoint value the run mentions."""
        for name, value in self.initial.fields.items():
            yield "initial", name, value
        for i, step in enumerate(self.steps):
            update = step.set if step.set is not None else step.ramp
            if update is None:
                continue
            kind = "set" if step.set is not None else "ramp"
            for name, value in update.fields.items():
                yield f"steps[{i}].{kind}", name, value

    def check_defects(self, geometry, where: str = "") -> None:
        """Raise ScenarioError for the first step whose `defects` this bearing cannot take
        (service.core.defects: the field and the bearing's own range)."""
        from service.core.defects import parse_defects
        from service.core.errors import InputError

        for i, step in enumerate(self.steps):
            if step.defects is None:
                continue
            try:
                parse_defects(step.defects, geometry, prefix=f"{where}steps[{i}].defects")
            except InputError as exc:
                e = exc.errors[0]
                raise ScenarioError(e.field or f"{where}steps[{i}].defects", e.message, e.allowed) from None

    def check_limits(self, limits: SetpointLimits, where: str = "") -> None:
        """Raise ScenarioError for the first value outside the bearing's limits (`Twin.limits`,
        `SetpointLimits.for_model`): what `scenario check`, `scenario run` and the service check.

        The limits are boxes per field, so a linear ramp between values inside them stays inside."""
        for place, name, value in self.iter_values():
            problems = limits.problems({name: value})
            if problems:
                p = problems[0]
                raise ScenarioError(
                    f"{where}{place}.{name}", p.message(limits.bearing or self.designation), [p.low, p.high]
                )
