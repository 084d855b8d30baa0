"""`bearing-twin attack`: a short run against its own real service on loopback (token,
zenoh access control): the report's structure, and no 5xx and no non-finite number in the
hostile HTTP flood, the unauthenticated read flood and the zenoh flood, every zenoh setpoint
answered; the zenoh squatter blocks nothing, no guessed OPC UA password is accepted, the OPC UA
session and subscription floods meet the guard's limits. The real-time factor and /health latency are reported, never
asserted (shared host)."""

from __future__ import annotations

import pytest

from loadtest.attack import AttackConfig, check_loopback, format_report, run_attack


def test_attack_short_run_with_its_own_service():
    # 8 s: the tarpit (on by default in the served process) slows the hostile flood down; it deals its
    # kinds from shuffled decks of 20, so every kind is sent once it has made 20 requests
    r = run_attack(AttackConfig(seconds=8.0, start=True, baseline_s=1.0, seed=7, zenoh_rate_hz=200.0))
    print("\n" + format_report(r))
    assert r["ok"], r["failures"]
    t = r["totals"]
    assert t["5xx"] == 0 and t["non_finite"] == 0 and t["transport_errors"] == 0
    assert t["2xx"] > 0 and t["4xx"] > 0 and t["nan_checked"] > 0
    hostile, reads, z = r["http_flood"], r["read_flood"], r["zenoh_flood"]
    assert hostile["workers"] == 32 and reads["workers"] == 4
    # the hostile mix was sent and refused as it should be
    assert sum(hostile["kinds"].values()) >= 20
    assert {"valid", "nan", "big", "no-token", "unknown-twin"} <= set(hostile["kinds"])
    assert {401, 413, 422} <= {int(code) for code in hostile["status"]}
    assert hostile["counts"].get("valid_refused", 0) == 0 and hostile["counts"].get("hostile_accepted", 0) == 0
    assert sum(reads["status"].values()) > 0
    assert z["sent"] > 0 and z["unanswered"] == 0 and z["non_finite"] == 0
    assert sum(z["results"].values()) == z["sent"]
    for phase in ("baseline", "flood"):
        f = r[phase]
        assert f["probes"] > 0 and f["failed"] == 0
        assert f["health_p99_ms"] is not None and f["real_time_factor_median"] is not None
    assert set(r["targets"]) == {
        "real_time_factor_median_min",
        "health_p99_ms_max",
        "real_time_factor_median",
        "health_p99_ms",
        "met",
    }
    assert r["shutdown"]["clean"]
    # the floods on what watchers use (loadtest.attack_watchers): the squatter (refused a link by
    # zenoh access control) blocks no create and no answer repeats it; no guessed password opens a
    # session; sessions, subscriptions and items stay within the default limits (service.opcua.guard)
    sq, logins, sessions, subs = (r[k] for k in ("squat", "opcua_logins", "opcua_sessions", "opcua_subscriptions"))
    # every create is admitted, or refused for the host's measured capacity (a slow host under the
    # floods has no room for a second twin): the admission decides, never the squatter's claim
    assert sq["attempts"] >= 1 and sq["created"] + sq["refused_capacity"] == sq["attempts"] and not sq["other"]
    assert sq["blocked"] == sq["echoed"] == 0
    assert logins["tried"] >= 1 and logins["accepted"] == 0
    assert 1 <= sessions["opened"] <= 16
    assert subs["subscriptions"] == 8 and subs["refused"]["BadTooManySubscriptions"] == 42
    assert subs["publishing_interval_ms"] == [50.0] and subs["items"] == 50  # 1000/s at 20/s per item
    assert subs["notifications_per_s"] <= 1000.0 * 1.2
    # the attackers' own CPU and the service's tarpit (on by default in a served process) are reported
    cpu = r["attacker_cpu_cores"]
    assert set(cpu) == {"http_flood", "read_flood", "zenoh_flood", "total"} and all(v >= 0 for v in cpu.values())
    tarpit = r["service"]["http_tarpit"]
    assert tarpit["active"] and tarpit["held_now"] >= 0 and tarpit["max_held"] == 64


@pytest.mark.parametrize(
    "url, zenoh",
    [("http://10.0.0.8:8000", None), ("http://example.org", None), ("http://127.0.0.1:8000", "tcp/192.168.1.4:7447")],
)
def test_attack_is_loopback_only(url, zenoh):
    with pytest.raises(ValueError, match="loopback"):
        check_loopback(url, zenoh)
    with pytest.raises(ValueError, match="loopback"):
        run_attack(AttackConfig(seconds=1.0, url=url, zenoh_connect=zenoh))


@pytest.mark.parametrize(
    "field, value",
    [("seconds", 601.0), ("seconds", float("inf")), ("seconds", 0.0), ("concurrency", 65), ("concurrency", 0)],
)
def test_attack_is_bounded(field, value):
    cfg = AttackConfig(seconds=1.0)
    setattr(cfg, field, value)
    with pytest.raises(ValueError, match=field):
        run_attack(cfg)


def test_a_squat_blocks_fail_the_verdict_only_against_a_secured_service():
    """docs/operations.md ("Twin-id claims on zenoh"): with nothing secured the service trusts
    every zenoh peer's claim, so a create the squatter blocked is reported, not a failure; with a
    token (or `--start`) it fails the verdict. An answer that repeats the squatter's text fails
    either way."""
    from loadtest.attack_watchers import failures, summary_lines

    squat = {"attempts": 3, "peer_linked": True, "created": 2, "refused_capacity": 0, "other": {}}
    open_service = {"squat": {**squat, "secure": False, "blocked": 1, "echoed": 0}}
    assert failures(open_service) == []
    assert "expected: with nothing secured" in summary_lines(open_service)[0]
    secured = {"squat": {**squat, "secure": True, "blocked": 1, "echoed": 0}}
    assert failures(secured) == ["1 twin creations blocked by a squatter zenoh did not authenticate"]
    assert "expected" not in summary_lines(secured)[0]
    echoed = {"squat": {**squat, "secure": False, "blocked": 0, "echoed": 1}}
    assert failures(echoed) == ["1 answers repeated the squatter's text"]
