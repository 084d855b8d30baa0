"""schemathesis against the service's OpenAPI: every operation, positive and negative
data generated from the spec, sent to a real uvicorn server on 127.0.0.1; the only check is
`not_a_server_error` (no 5xx). Bounded: a few dozen examples per operation and mode, no
shrinking; part of the normal pytest run (about a minute on the project's 2-core VM)."""

from __future__ import annotations

import pytest

schemathesis = pytest.importorskip("schemathesis")
from hypothesis import HealthCheck, settings  # noqa: E402
from schemathesis.checks import not_a_server_error  # noqa: E402

from service.api.app import create_app  # noqa: E402
from service.settings import ServiceSettings  # noqa: E402

EXAMPLES = 60


def _settings(tmp=None, scenarios=None) -> ServiceSettings:
    kw = {"record": tmp / "rec" / "service.rrd"} if tmp is not None else {}
    if scenarios is not None:
        kw["scenario_dir"] = scenarios
    return ServiceSettings(
        enable_zenoh=False, enable_recording=True, max_twins=3, setpoint_rate_hz=0.0, max_body_bytes=16 * 1024, **kw
    )


# the spec comes from the app factory itself (no server needed to collect the tests)
schema = schemathesis.openapi.from_dict(create_app(_settings()).openapi())
schema.config.generation.update(max_examples=EXAMPLES, no_shrink=True, deterministic=True)


@pytest.fixture(scope="module")
def base_url(hostile, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("schemathesis")
    with hostile.ThreadServer(_settings(tmp, hostile.SCENARIOS)) as srv:
        yield srv.url
        # the service is still alive and finite afterwards
        import httpx

        with httpx.Client(base_url=srv.url, timeout=30.0) as c:
            assert c.get("/health").status_code == 200
            for tw in c.get("/health").json()["twins"]:
                state = c.get(f"/v1/bearings/{tw['id']}/state")
                assert state.status_code == 200
                hostile.strict_loads(state.content)


@schema.parametrize()
@settings(max_examples=EXAMPLES, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
def test_no_server_errors(case, base_url):
    case.call_and_validate(base_url=base_url, checks=[not_a_server_error], timeout=30)
