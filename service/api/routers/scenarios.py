"""Scenarios: the named ones, and a twin's running (or last) scenario: start, show, cancel."""

from __future__ import annotations

from fastapi import APIRouter

from service.api.deps import SettingsDep, TwinDep
from service.api.routers.bearings import INVALID, UNKNOWN_TWIN
from service.api.schemas import ScenarioAccepted, ScenarioList, ScenarioRequest, ScenarioStatus
from service.core.errors import InputError
from service.core.scenario_files import find_scenario, list_scenarios, load_scenario, scenario_from_dict
from service.core.scenarios import ScenarioError

read = APIRouter(tags=["scenarios"])
write = APIRouter(tags=["scenarios"])


@read.get("/v1/scenarios", response_model=ScenarioList)
def get_scenarios(settings: SettingsDep) -> ScenarioList:
    """Named scenarios (files in the scenarios directory)."""
    directory = settings.twin.scenarios_path
    out: dict[str, str] = {}
    for name, path in list_scenarios(directory).items():
        try:
            out[name] = load_scenario(path).description.strip()
        except ScenarioError as exc:
            out[name] = f"(invalid: {exc})"
    return ScenarioList(directory=str(directory), scenarios=out)


@read.get(
    "/v1/bearings/{bearing_id}/scenario", response_model=ScenarioStatus | None, responses={**UNKNOWN_TWIN, **INVALID}
)
def get_scenario(entry: TwinDep) -> ScenarioStatus | None:
    """The running (or last) scenario of this twin, null if none ran."""
    handle = entry.runner.scenario
    return ScenarioStatus(**handle.status()) if handle is not None else None


@write.post(
    "/v1/bearings/{bearing_id}/scenario",
    response_model=ScenarioAccepted,
    status_code=202,
    responses={**UNKNOWN_TWIN, **INVALID},
)
def post_scenario(entry: TwinDep, body: ScenarioRequest, settings: SettingsDep) -> ScenarioAccepted:
    """Run a named scenario (scenarios/<name>.yaml) or an inline one on this twin, in its
    runner (a scenario already running is cancelled). Returns at once."""
    if (body.name is None) == (body.scenario is None):
        raise InputError.one(
            "name",
            "give either 'name' (a scenario file) or 'scenario' (inline)",
            sorted(list_scenarios(settings.twin.scenarios_path)),
        )
    if body.name is not None:
        scenario = find_scenario(body.name, settings.twin.scenarios_path)
    else:
        try:
            scenario = scenario_from_dict(body.scenario)
        except ScenarioError as exc:
            raise ScenarioError(f"scenario.{exc.field}", exc.message, exc.allowed) from None
    runs = scenario.resolved_runs()
    if body.run is None:
        run = runs[0]
    else:
        matching = [r for r in runs if r.id == body.run]
        if not matching:
            raise InputError.one("run", f"scenario {scenario.name!r} has no run {body.run!r}", [r.id for r in runs])
        run = matching[0]
    run.check_twin(
        entry.designation,
        entry.diametral_clearance_m,
        entry.lubricant,
        entry.twin.model.spec.thermal,
        spec=entry.twin.model.spec,
    )
    _handle, replaced = entry.runner.start_scenario(run, restart=body.restart)
    return ScenarioAccepted(
        accepted=True,
        bearing_id=entry.id,
        name=scenario.name,
        run=run.id,
        expected_duration_s=run.duration_s,
        mode=entry.runner.mode,
        replaced=replaced.name if replaced is not None else None,
        warnings=scenario.warnings,
    )


@write.delete(
    "/v1/bearings/{bearing_id}/scenario", response_model=ScenarioStatus | None, responses={**UNKNOWN_TWIN, **INVALID}
)
def cancel_scenario(entry: TwinDep) -> ScenarioStatus | None:
    """Cancel the running scenario; the setpoint stays where the scenario left it."""
    handle = entry.runner.cancel_scenario()
    return ScenarioStatus(**handle.status()) if handle is not None else None
