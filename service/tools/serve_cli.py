"""`bearing-twin serve`: the service in one uvicorn worker, its settings from the BEARING_TWIN_*
environment and the flags (service.tools.settings_flags). service/tools/cli.py registers it with
`add_serve_command(sub)`.
"""

from __future__ import annotations

import argparse
import sys

from service.settings import ServiceSettings
from service.tools.messages import error_text
from service.tools.settings_flags import add_settings_flags, flag_overrides, settings_error_text


def add_serve_command(sub) -> None:
    """Register `serve` on the `bearing-twin` subparsers."""
    serve = sub.add_parser(
        "serve",
        help="run the service: HTTP API, zenoh bus, rerun recording, the `default` twin",
        description="Run the service (one uvicorn worker). Each flag overrides its BEARING_TWIN_* "
        "environment variable, which overrides the built-in default (docs/configuration.md). Secrets "
        "(BEARING_TWIN_TOKEN, BEARING_TWIN_ZENOH_PASSWORD) come from the environment only.",
    )
    add_settings_flags(serve, ServiceSettings)
    serve.add_argument("--log-level", default="info", choices=["critical", "error", "warning", "info", "debug"])
    serve.set_defaults(func=_cmd_serve)


def serve_settings(args: argparse.Namespace) -> ServiceSettings:
    """BEARING_TWIN_* environment + the flags that were given; `--record PATH` also turns the
    recording on."""
    overrides = flag_overrides(args)
    recording = overrides.get("recording", {})
    if "path" in recording:
        recording.setdefault("enabled", True)
    return ServiceSettings(**overrides)


def _cmd_serve(args: argparse.Namespace) -> int:
    import logging

    from pydantic import ValidationError
    from pydantic_settings import SettingsError

    from twin import catalog

    try:
        settings = serve_settings(args)
    except ValidationError as exc:
        print(f"error: {settings_error_text(exc, ServiceSettings)}", file=sys.stderr)
        return 2
    except SettingsError as exc:  # an environment value that is not JSON where JSON is due
        print(f"error: {exc}", file=sys.stderr)
        return 2
    given = vars(args)
    if "recording.path" in given and given.get("recording.enabled") is False:
        print("error: --record and --no-record contradict each other", file=sys.stderr)
        return 2
    try:
        default_spec = catalog.bearing_or_file(settings.twin.bearing)
    except ValidationError as exc:
        print(f"error: bearing: {settings.twin.bearing}: {error_text(exc)}", file=sys.stderr)
        return 2
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2

    from service.api.app import create_app
    from service.settings import is_loopback_host

    logging.basicConfig(
        level=getattr(logging, args.log_level.upper()), format="%(asctime)s %(levelname)s %(name)s: %(message)s"
    )
    host = settings.http.host
    where = "loopback only; --host 0.0.0.0 to expose it" if is_loopback_host(host) else "reachable from other machines"
    port = settings.http.port if settings.http.port else "<a free port, see uvicorn's line below>"
    print(
        f"bearing-twin: HTTP on http://{host}:{port} ({where}); "
        f"twin `{settings.twin.id}` = {default_spec.designation}, {'fast' if settings.runner.fast else 'real-time'} "
        f"mode",
        flush=True,
    )
    from service.api.app import access_summary

    print(
        f"bearing-twin: access: {access_summary(settings)}; setpoints limited to "
        + (
            f"{settings.security.setpoint_rate_hz:g}/s per twin (bursts of {settings.security.setpoint_burst})"
            if settings.security.setpoint_rate_hz
            else "no rate"
        )
        + f"; request bodies up to {settings.security.max_body_bytes} bytes",
        flush=True,
    )
    if settings.zenoh.enabled:
        from service.bus.access import ZenohAccess

        print(
            f"bearing-twin: zenoh {settings.zenoh.mode} listening on {', '.join(settings.zenoh.listen) or 'nothing'}"
            + (f", connecting to {', '.join(settings.zenoh.connect)}" if settings.zenoh.connect else "")
            + f", keys {settings.zenoh.prefix}/<id>/...",
            flush=True,
        )
        zenoh_access = ZenohAccess.from_settings(settings.zenoh, enforce=True).describe(
            listening=bool(settings.zenoh.listen)
        )
        if not settings.zenoh.access_control and settings.security.token is not None:
            zenoh_access += "; zenoh setpoints refused (the HTTP API needs a token)"
        print(f"bearing-twin: {zenoh_access}", flush=True)
    else:
        print("bearing-twin: zenoh off", flush=True)
    if settings.opcua.endpoint:
        security = settings.opcua_security_mode
        print(
            f"bearing-twin: OPC UA on {settings.opcua.endpoint} (namespace urn:bearing-twin:opcua; "
            + ("user name + the token as password to write" if settings.security.token else "anonymous writes allowed")
            + "; security "
            + {
                "none": "None only" + (": the password crosses in clear" if settings.security.token else ""),
                "sign": "Sign",
                "sign_and_encrypt": "SignAndEncrypt",
                "both": "Sign and SignAndEncrypt",
                "all": "Sign, SignAndEncrypt and None (anonymous reads)",
            }[security]
            + (" with Basic256Sha256, Aes128_Sha256_RsaOaep, Aes256_Sha256_RsaPss" if security != "none" else "")
            + (
                f"; clients trusted: the certificates in {settings.opcua.trusted_dir}"
                if settings.opcua.trusted_dir is not None
                else ""
            )
            + ")",
            flush=True,
        )
    from service.core.errors import InputError
    from service.wiring import TwinService, WiringError
    from twin.jit import engine_cache_is_empty

    if engine_cache_is_empty():
        print(
            "bearing-twin: compiling the engine (numba), once per installed version: a minute or two "
            "before HTTP answers",
            flush=True,
        )
    # open the twins, zenoh and the recording here, before uvicorn: what fails (a zenoh port in
    # use, a recording path that cannot be written) is one line, like a busy HTTP port
    try:
        service = TwinService(settings).open()
    except (WiringError, InputError, OSError) as exc:
        print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    pki = getattr(getattr(service, "opcua", None), "pki", None)
    if pki is not None:
        print(
            f"bearing-twin: OPC UA server certificate {pki.certificate} (SHA-1 thumbprint "
            f"{pki.thumbprint_sha1}, valid until {pki.not_after:%Y-%m-%d}): trust it in the clients",
            flush=True,
        )
    recorder = getattr(service, "recorder", None)
    written = getattr(recorder, "path", None) if recorder is not None else None
    if written is not None:  # the file actually written: <stem>.run2.rrd when the name was taken
        print(f"bearing-twin: recording to {written}", flush=True)
    else:
        print(
            "bearing-twin: not recording"
            if settings.recording.active_path is None
            else f"bearing-twin: recording to {settings.recording.active_path}",
            flush=True,
        )
    from service.api.server import uvicorn_config

    config = uvicorn_config(
        create_app(settings, service=service),
        settings,
        host=host,
        log_level=args.log_level,
        timeout_graceful_shutdown=3,
    )
    server = _InterruptibleServer(config)
    try:
        server.run()
    except KeyboardInterrupt:
        # uvicorn re-raises a captured SIGINT (Ctrl-C) once its graceful shutdown - our lifespan
        # `finally`: runners stopped, zenoh closed, recordings flushed - is complete
        return 130
    if server.interrupted:  # the re-raise can be absorbed by asyncio's own SIGINT handling
        return 130
    return 0 if server.started else 1


def _interruptible_server_class():
    import signal

    import uvicorn

    class InterruptibleServer(uvicorn.Server):
        """uvicorn's server that remembers a SIGINT (Ctrl-C), so that `serve` exits with 130 after
        its graceful shutdown whether or not uvicorn's re-raised signal reaches us as
        KeyboardInterrupt (asyncio.Runner's own SIGINT handler may turn it into a cancellation)."""

        interrupted = False

        def handle_exit(self, sig, frame) -> None:
            if sig == signal.SIGINT:
                self.interrupted = True
            super().handle_exit(sig, frame)

    return InterruptibleServer


def _InterruptibleServer(config):
    return _interruptible_server_class()(config)
