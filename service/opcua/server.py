"""`OpcUaFacade`: the twins of a service as an OPC UA server (asyncua), in its own thread.

    facade = OpcUaFacade(registry, "opc.tcp://127.0.0.1:4840").start()   # listening on return
    registry.alarms.subscribe(facade.on_alarm)                           # alarms as OPC UA events
    facade.close()

The server runs its own asyncio loop in a daemon thread. Every half publish period it reads each
twin's latest published snapshot (`runner.latest`, no work on the stepping threads) and, when
the snapshot is new, writes the variables that changed; twins created or deleted in the
registry appear or disappear at the same pace. Address space: service.opcua.layout (docs/service.md
"OPC UA"); the nodes of a twin: service.opcua.nodes; the users: service.opcua.identity.

Writes. The Setpoint variables, and with a thermal network the MeasuredTemperature variables
(`outer_ring_c`, `housing_c`, `oil_c`), are answered by `_GatedAttributeService` (it replaces
asyncua's attribute service and passes every other write on): the same admission gate and paths
as HTTP and zenoh (service.core.admission; `runner.submit` -> `SetpointLimits.admit`, or
`runner.submit_temperature`). Status codes: BadUserAccessDenied (a token is set and the session
is anonymous), BadTooManyOperations (the twin's setpoint rate, which measurements share),
BadTypeMismatch (not a number), BadOutOfRange (outside the bearing's range or the measurement's,
or not finite). The OPC UA write response carries only the status code, so the words (naming the
field and its range, as the HTTP 422) go to the folder's `last_result` variable, JSON like the
zenoh result key:
{"accepted": false, "status": "BadOutOfRange", "field": "radial_load_n", "error": "..."}.

Users. The bearer token is the password of a user-name identity (any user name); a wrong
password refuses the session (BadUserAccessDenied at ActivateSession). With a token set,
anonymous sessions read (unless `read_requires_token`, then they are refused) but cannot write.
Without a token anyone may write, as over HTTP.

Security (service.opcua.security; setting `opcua_security`, `auto` = `both` with a token, else
`none`). The secure modes offer Basic256Sha256, Aes128_Sha256_RsaOaep and Aes256_Sha256_RsaPss in
Sign and/or SignAndEncrypt with the server certificate `opcua_certificate` / `opcua_private_key`,
or a self-signed one made once in `opcua_pki_dir` (key 0600, never overwritten; its SHA-1
thumbprint is logged at start and kept in `facade.pki`). Rules of a secure server:
- Every secure endpoint's user-name policy asks for the password RSA-encrypted with the server's
  key under the endpoint's own policy (`TokenServer`; asyncua would leave it in clear inside
  SignAndEncrypt); `TokenUserManager` refuses a password that came unencrypted
  (BadIdentityTokenRejected, the password is not tried).
- asyncua opens a None channel even when None is not offered (discovery needs one): no session
  is activated on it (BadSecurityPolicyRejected). In mode `all` None is offered for anonymous
  read-only sessions; a user name there is refused (BadIdentityTokenRejected): writes only come
  over a signed channel.
- With `opcua_trusted_dir`, only clients whose certificate (or its CA) is in that folder get a
  session (BadCertificateUntrusted): asyncua's CertificateValidator + TrustStore check the
  certificate announced at CreateSession, and `TokenUserManager` checks again, at
  ActivateSession, the certificate the secure channel was really opened with (asyncua does not
  compare the two).
`opcua_security = none` with a token sends the password in clear: an explicit choice,
warned about in the log.

Limits (service.opcua.guard): sessions, subscriptions and monitored items per session, the
notifications a session may cause per second, and a backoff of failed logins per client
address; `facade.guard.figures()` counts what was refused.
"""

from __future__ import annotations

import asyncio
import json
import logging
import math
import threading
from datetime import UTC
from typing import Any
from urllib.parse import urlparse

from asyncua import ua
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.server.address_space import AttributeService
from asyncua.server.event_generator import EventGenerator

from service.core.alarm_inputs import inputs_from_snapshot
from service.core.alarms import AlarmEvent
from service.core.errors import InputError
from service.core.measured_temperature import TEMPERATURE_RANGE_C, parse_measured_temperature
from service.opcua.guard import OpcUaGuard
from service.opcua.identity import TokenServer, TokenUserManager
from service.opcua.layout import (
    APPLICATION_URI,
    EVENT_TYPE,
    FOLDERS,
    LAST_RESULT,
    MEASURED_TEMPERATURE,
    MEASURED_TEMPERATURE_VARS,
    NAMESPACE_URI,
    ROOT_FOLDER,
    SETPOINT_VARS,
    Var,
    View,
    identification,
)
from service.opcua.nodes import EVENT_FIELDS, NUMERIC_TYPES, VARIANT_TYPES, TwinNodes, node_id, status_code
from service.opcua.security import POLICIES, ClientTrust, PkiError, ServerPki, given_pki, self_signed_pki

log = logging.getLogger(__name__)


class OpcUaError(RuntimeError):
    """The OPC UA server could not start (e.g. the port is taken)."""


_ADMIN = User(role=UserRole.Admin)  # asyncua's default user of a server-side write


class _GatedAttributeService(AttributeService):
    """asyncua's attribute service with the input variables (Setpoint, MeasuredTemperature)
    answered by the facade."""

    def __init__(self, aspace: Any, facade: OpcUaFacade):
        super().__init__(aspace)
        self._facade = facade

    async def write(self, params: ua.WriteParameters, user: User = _ADMIN) -> list[ua.StatusCode]:
        inputs = self._facade._input_nodes
        if user.role == UserRole.Admin or not any(w.NodeId in inputs for w in params.NodesToWrite):
            return await super().write(params, user)  # the server's own writes, other nodes
        results: list[ua.StatusCode] = []
        for w in params.NodesToWrite:
            if w.NodeId in inputs:
                results.append(await self._facade._write_input(w, inputs[w.NodeId], user))
            else:
                results.extend(await super().write(ua.WriteParameters(NodesToWrite=[w]), user))
        return results


class OpcUaFacade:
    """The OPC UA server of a service (see the module docstring)."""

    def __init__(
        self,
        registry: Any,
        endpoint: str,
        *,
        period_s: float | None = None,
        read_requires_token: bool | None = None,
        server_name: str = "bearing-twin",
        security: str | None = None,
    ):
        parsed = urlparse(endpoint)
        if parsed.scheme != "opc.tcp" or not parsed.hostname or parsed.port is None:
            raise ValueError(f"opcua = {endpoint!r}: expected opc.tcp://HOST:PORT[/path]")
        settings = registry.settings
        # security: the mode (docs/service.md "OPC UA"); the certificate, key and folders from the settings
        self.security = security if security is not None else settings.opcua_security_mode
        if self.security not in POLICIES:
            raise ValueError(f"opcua_security = {self.security!r}: expected one of {', '.join(POLICIES)}")
        self.pki: ServerPki | None = None  # the server certificate in use (secure modes)
        self.trust: ClientTrust | None = None
        self.guard = OpcUaGuard.from_settings(settings)
        self.registry = registry
        self.endpoint = endpoint
        # one publish period (of wall time; in fast mode of simulated time, at least 10 ms)
        self.period_s = (
            float(period_s)
            if period_s
            else max(1.0 / settings.runner.publish_rate_hz, 0.01 if settings.runner.fast else 0.0)
        )
        self.read_requires_token = (
            settings.security.read_requires_token if read_requires_token is None else read_requires_token
        )
        self.server_name = server_name
        self.url: str | None = None  # the endpoint actually listened on
        self.namespace_index: int | None = None
        self.updates = 0
        self.events_sent = 0
        self._input_nodes: dict[ua.NodeId, tuple[str, str, str]] = {}  # -> (twin id, folder, name)
        self._twins: dict[str, TwinNodes] = {}
        self._loop: asyncio.AbstractEventLoop | None = None
        self._alarms: asyncio.Queue | None = None
        self._stop: asyncio.Event | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._thread: threading.Thread | None = None

    # ---- life cycle (any thread) ---------------------------------------------------------------
    def start(self, timeout_s: float = 60.0) -> OpcUaFacade:
        """Start the server thread; return once it listens (OpcUaError if it cannot)."""
        logging.getLogger("asyncua").setLevel(max(logging.WARNING, logging.getLogger("asyncua").level))
        # asyncua's TrustStore logs each untrusted certificate with a traceback; the facade logs one line
        logging.getLogger("asyncuagds.validate").setLevel(logging.CRITICAL)
        self._thread = threading.Thread(target=self._thread_main, name="opcua", daemon=True)
        self._thread.start()
        if not self._ready.wait(timeout_s):
            self.close()
            raise OpcUaError(f"OPC UA server on {self.endpoint} did not start within {timeout_s:g} s")
        if self._error is not None:
            self._thread.join(5.0)
            raise OpcUaError(f"OPC UA server on {self.endpoint}: {' '.join(str(self._error).split())}") from self._error
        return self

    def close(self, timeout_s: float = 10.0) -> None:
        """Stop the server and its thread (idempotent)."""
        loop, stop = self._loop, self._stop
        if loop is not None and stop is not None and not loop.is_closed():
            try:
                loop.call_soon_threadsafe(stop.set)
            except RuntimeError:
                pass  # the loop already ended
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout_s)

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive() and self._ready.is_set() and self._error is None

    def on_alarm(self, event: AlarmEvent) -> None:
        """Alarm hub subscriber: queue the event for the server's loop (never blocks)."""
        loop, q = self._loop, self._alarms
        if loop is None or q is None or loop.is_closed():
            return
        try:
            loop.call_soon_threadsafe(q.put_nowait, event)
        except RuntimeError:
            pass

    # ---- the server's thread -------------------------------------------------------------------
    def _thread_main(self) -> None:
        try:
            asyncio.run(self._main())
        except BaseException as exc:
            if not self._ready.is_set():
                self._error = exc
                self._ready.set()
            else:
                log.exception("OPC UA server stopped")

    async def _main(self) -> None:
        self._loop = asyncio.get_running_loop()
        self._alarms = asyncio.Queue()
        self._stop = asyncio.Event()
        secure = self.security != "none"
        settings = self.registry.settings
        if secure:
            await self._load_pki(settings)
        elif self.registry.gate.requires_token:
            log.warning(
                "OPC UA: opcua_security = none with a token: the token (the OPC UA password) "
                "crosses the network in clear"
            )
        users = TokenUserManager(
            self.registry.gate,
            self.read_requires_token,
            secure=secure,
            none_offered=ua.SecurityPolicyType.NoSecurity in POLICIES[self.security],
            trust=self.trust,
        )
        server = self.server = TokenServer(user_manager=users)
        server.secure = secure
        await server.init()
        users.wrap(server.iserver)
        self.guard.install(server.iserver)
        server.set_endpoint(self.endpoint)
        server.set_server_name(self.server_name)
        await server.set_application_uri(APPLICATION_URI)
        if self.pki is not None:
            await server.load_certificate(str(self.pki.certificate))
            await server.load_private_key(str(self.pki.private_key))
        if self.trust is not None:
            server.set_certificate_validator(self.trust.validator())
        server.set_security_policy(list(POLICIES[self.security]))
        server.set_identity_tokens([ua.AnonymousIdentityToken, ua.UserNameIdentityToken])
        server.iserver.attribute_service = _GatedAttributeService(server.iserver.aspace, self)
        idx = self.namespace_index = await server.register_namespace(NAMESPACE_URI)
        self._root = await server.nodes.objects.add_folder(
            node_id(ROOT_FOLDER, idx), ua.QualifiedName(ROOT_FOLDER, idx)
        )
        self._event_type = await server.create_custom_event_type(
            idx, EVENT_TYPE, ua.ObjectIds.BaseEventType, list(EVENT_FIELDS)
        )
        await server.start()
        try:
            # the port really bound (0: any); asyncua types its listener as an AbstractServer
            sock = server.bserver._server.sockets[0].getsockname()  # type: ignore[union-attr]
            self.url = f"opc.tcp://{urlparse(self.endpoint).hostname}:{sock[1]}{urlparse(self.endpoint).path}"
        except Exception:  # noqa: BLE001
            self.url = self.endpoint
        log.info("OPC UA server on %s (namespace %s), security %s", self.url, NAMESPACE_URI, self.security)
        self._ready.set()
        try:
            while not self._stop.is_set():
                try:
                    await self._sync()
                    await self._send_alarms()
                    self.guard.logins.sweep()
                except Exception:
                    log.exception("OPC UA update failed")
                try:
                    await asyncio.wait_for(self._stop.wait(), timeout=0.5 * self.period_s)
                except TimeoutError:
                    pass
        finally:
            await server.stop()

    async def _load_pki(self, settings: Any) -> None:
        """The server certificate (given or self-signed in opcua_pki_dir) and the trusted clients."""
        given = settings.opcua.certificate
        host = urlparse(self.endpoint).hostname or ""
        try:
            if given is not None:
                self.pki = await asyncio.to_thread(given_pki, given, settings.opcua.private_key, APPLICATION_URI)
            else:
                self.pki = await asyncio.to_thread(
                    self_signed_pki,
                    settings.opcua.pki_dir,
                    APPLICATION_URI,
                    [host] if host not in ("0.0.0.0", "::") else [],
                )
            trusted = settings.opcua.trusted_dir
            if trusted is not None:
                self.trust = await ClientTrust(trusted).load()
        except PkiError as exc:
            raise OpcUaError(str(exc)) from None
        pki = self.pki
        made = " (made now)" if pki.generated_certificate else ""
        log.info(
            "OPC UA server certificate %s%s: SHA-1 thumbprint %s, valid until %s; key %s",
            pki.certificate,
            made,
            pki.thumbprint_sha1,
            f"{pki.not_after:%Y-%m-%d}",
            pki.private_key,
        )
        if self.trust is not None:
            log.info(
                "OPC UA: only clients with a certificate in %s (%d file(s)) may open a session",
                self.trust.folder,
                self.trust.count,
            )

    # ---- twins ---------------------------------------------------------------------------------
    async def _sync(self) -> None:
        entries = {e.id: e for e in self.registry.entries()}
        for gone in [i for i in self._twins if i not in entries]:
            await self._remove_twin(gone)
        for bearing_id, entry in entries.items():
            nodes = self._twins.get(bearing_id)
            if nodes is None:
                nodes = await self._add_twin(entry)
            await self._update(nodes, entry)

    def _namespace(self) -> int:
        """The service's namespace index (registered when the server starts)."""
        assert self.namespace_index is not None
        return self.namespace_index

    def _nid(self, *parts: str) -> ua.NodeId:
        return node_id("/".join(parts), self._namespace())

    async def _add_twin(self, entry: Any) -> TwinNodes:
        obj = await self._root.add_object(self._nid(entry.id), ua.QualifiedName(entry.id, self._namespace()))
        try:
            return await self._populate(entry, obj)
        except BaseException:
            self._forget_inputs(entry.id)
            await self.server.delete_nodes([obj], recursive=True)  # tried again next time
            raise

    async def _populate(self, entry: Any, obj: Any) -> TwinNodes:
        idx, bid = self._namespace(), entry.id
        qn = lambda name: ua.QualifiedName(name, idx)  # noqa: E731
        nodes = TwinNodes(bid, obj)
        ident = await obj.add_folder(self._nid(bid, "Identification"), qn("Identification"))
        for name, vtype, desc, value in identification(entry):
            vt = VARIANT_TYPES[vtype]
            node = await ident.add_variable(
                self._nid(bid, "Identification", name),
                qn(name),
                ua.Variant(value if value is not None else ua.get_default_value(vt), vt),
                varianttype=vt,
            )
            await node.write_attribute(ua.AttributeIds.Description, ua.DataValue(ua.Variant(ua.LocalizedText(desc))))
            if value is None:
                await self.server.write_attribute_value(node.nodeid, ua.DataValue(StatusCode=status_code("BadNoValue")))
        inputs: dict[str, tuple[Var, ...]] = {"Setpoint": SETPOINT_VARS}
        if entry.runner.twin.thermal is not None:  # a thermal network to follow a measurement
            inputs[MEASURED_TEMPERATURE] = MEASURED_TEMPERATURE_VARS
        for folder, variables in (*FOLDERS.items(), *inputs.items()):
            fnode = await obj.add_folder(self._nid(bid, folder), qn(folder))
            for var in variables:
                vt = VARIANT_TYPES[var.type]
                node = await fnode.add_variable(
                    self._nid(bid, folder, var.name),
                    qn(var.name),
                    ua.Variant(ua.get_default_value(vt), vt),
                    varianttype=vt,
                )
                await self.server.write_attribute_value(
                    node.nodeid, ua.DataValue(StatusCode=status_code("BadWaitingForInitialData"))
                )
                await node.write_attribute(
                    ua.AttributeIds.Description, ua.DataValue(ua.Variant(ua.LocalizedText(var.description)))
                )
                nodes.vars[f"{folder}/{var.name}"] = (node.nodeid, vt, var.read)
                if folder in inputs:
                    await node.set_writable(True)
                    low, high = entry.runner.limits[var.name] if folder == "Setpoint" else TEMPERATURE_RANGE_C
                    await node.add_property(
                        self._nid(bid, folder, var.name, "EURange"), qn("EURange"), ua.Range(low, high)
                    )
                    self._input_nodes[node.nodeid] = (bid, folder, var.name)
            if folder in inputs:
                last = await fnode.add_variable(
                    self._nid(bid, folder, LAST_RESULT), qn(LAST_RESULT), "", varianttype=ua.VariantType.String
                )
                await last.write_attribute(
                    ua.AttributeIds.Description,
                    ua.DataValue(
                        ua.Variant(
                            ua.LocalizedText(
                                f"What became of the latest write to a {folder} variable, JSON: accepted, status, "
                                "field, error naming the field and its range [text]."
                            )
                        )
                    ),
                )
                nodes.last_results[folder] = last.nodeid
        # alarm events: from the twin object, and from the Server object (SourceNode = the twin)
        isession = self.server.iserver.isession
        for emitter, add_ref in ((obj.nodeid, True), (node_id(ua.ObjectIds.Server), False)):
            gen = EventGenerator(isession)
            await gen.init(self._event_type, emitting_node=emitter, add_generates_event=add_ref)
            gen.event.SourceNode, gen.event.SourceName = obj.nodeid, bid
            nodes.generators.append(gen)
        self._twins[bid] = nodes
        log.info("OPC UA: twin %s added", bid)
        return nodes

    async def _remove_twin(self, bearing_id: str) -> None:
        nodes = self._twins.pop(bearing_id)
        self._forget_inputs(bearing_id)
        await self.server.delete_nodes([nodes.obj], recursive=True)
        log.info("OPC UA: twin %s removed", bearing_id)

    def _forget_inputs(self, bearing_id: str) -> None:
        for nid in [n for n, (b, _f, _n) in self._input_nodes.items() if b == bearing_id]:
            del self._input_nodes[nid]

    async def _update(self, nodes: TwinNodes, entry: Any) -> None:
        snap = entry.runner.latest
        seq = None if snap is None else snap.seq
        target = entry.runner.target_setpoint
        if seq is not None and seq == nodes.seq and nodes.last.get("Setpoint/_target") is target:
            return
        nodes.seq = seq
        nodes.last["Setpoint/_target"] = target
        hub = self.registry.alarms
        settings = hub.settings
        view = View(
            snapshot=snap,
            inputs=inputs_from_snapshot(snap, settings) if snap is not None else None,
            alarms={a.alarm_id: a for a in hub.states(entry.id)},
            target=target,
            settings=settings,
            measured=getattr(entry, "measured", None) and entry.measured.latest,
        )
        now = ua.DateTime.now(UTC)
        for key, (nid, vt, read) in nodes.vars.items():
            try:
                value = read(view)
            except Exception:  # noqa: BLE001 - one bad reader never stops the others
                value = None
            if isinstance(value, float) and not math.isfinite(value):
                value = None
            if key in nodes.last and nodes.last[key] == value:
                continue
            nodes.last[key] = value
            if value is None:
                dv = ua.DataValue(
                    StatusCode=status_code("BadNoValue" if snap is not None else "BadWaitingForInitialData"),
                    SourceTimestamp=now,
                    ServerTimestamp=now,
                )
            else:
                dv = ua.DataValue(
                    ua.Variant(float(value) if vt == ua.VariantType.Double else value, vt),
                    SourceTimestamp=now,
                    ServerTimestamp=now,
                )
            await self.server.write_attribute_value(nid, dv)
        self.updates += 1

    # ---- alarms --------------------------------------------------------------------------------
    async def _send_alarms(self) -> None:
        while self._alarms is not None and not self._alarms.empty():
            event: AlarmEvent = self._alarms.get_nowait()
            nodes = self._twins.get(event.bearing_id)
            if nodes is None:
                continue
            for gen in nodes.generators:
                ev = gen.event
                ev.Severity = event.opcua_severity
                for name, _vt in EVENT_FIELDS:
                    value = event.severity if name == "level" else getattr(event, name)
                    setattr(ev, name, "" if value is None and name == "level" else value)
                await gen.trigger(message=event.message)
            self.events_sent += 1

    # ---- setpoint writes (server loop) ---------------------------------------------------------
    async def _write_input(self, w: ua.WriteValue, target: tuple[str, str, str], user: User) -> ua.StatusCode:
        """A write to a Setpoint or MeasuredTemperature variable: the token, the number, the
        twin's setpoint budget, then `runner.submit` or `runner.submit_temperature` (module
        docstring, "Writes"); the words go to the folder's `last_result`."""
        bearing_id, folder, name = target
        nodes = self._twins.get(bearing_id)
        result_node = nodes.last_results.get(folder) if nodes is not None else None

        async def answer(status: str, message: str | None = None, **extra: Any) -> ua.StatusCode:
            if result_node is not None:
                body = {"accepted": status == "Good", "status": status, "field": name, **extra}
                if message is not None:
                    body["error"] = message
                await self.server.write_attribute_value(
                    result_node,
                    ua.DataValue(ua.Variant(json.dumps(body, allow_nan=False), ua.VariantType.String)),
                )
            return status_code(status) if status != "Good" else ua.StatusCode()

        if w.AttributeId != ua.AttributeIds.Value:
            return status_code("BadNotWritable")
        gate = self.registry.gate
        if gate.requires_token and not getattr(user, "authenticated", False):
            refusal = gate.check_token(
                None,
                missing="anonymous writes are refused: this service has a token; "
                "connect with a user name and the token as password",
            )
            return await answer("BadUserAccessDenied", refusal.message if refusal else None)
        variant = w.Value.Value if w.Value is not None else None
        if variant is None or variant.VariantType not in NUMERIC_TYPES or variant.is_array:
            kind = "nothing" if variant is None else variant.VariantType.name
            return await answer("BadTypeMismatch", f"{name}: a number (Double), got {kind}")
        value = variant.Value
        entry = self.registry.find(bearing_id)
        if entry is None:
            return await answer("BadNodeIdUnknown", f"twin {bearing_id!r} is gone")
        refusal = gate.take_setpoint(bearing_id)
        if refusal is not None:
            return await answer("BadTooManyOperations", refusal.message, retry_after_s=refusal.retry_after_s)
        number = float(value) if variant.VariantType in (ua.VariantType.Double, ua.VariantType.Float) else int(value)
        if folder == MEASURED_TEMPERATURE:
            return await self._measure_temperature(entry, name, float(number), answer)
        try:
            setpoint = entry.runner.submit({name: number})
        except InputError as exc:
            out_of_range = (not math.isfinite(number)) or bool(entry.runner.limits.problems({name: number}))
            return await answer("BadOutOfRange" if out_of_range else "BadTypeMismatch", str(exc))
        if nodes is not None:
            nid = self._nid(bearing_id, "Setpoint", name)
            await self.server.write_attribute_value(
                nid, ua.DataValue(ua.Variant(float(getattr(setpoint, name)), ua.VariantType.Double))
            )
            nodes.last[f"Setpoint/{name}"] = getattr(setpoint, name)
        return await answer("Good", setpoint=setpoint.model_dump())

    async def _measure_temperature(self, entry: Any, name: str, value_c: float, answer: Any) -> ua.StatusCode:
        """`runner.submit_temperature` of the node `name` names (`outer_ring_c` -> outer_ring)."""
        node = name.removesuffix("_c")
        try:
            entry.runner.submit_temperature(parse_measured_temperature({"node": node, "temperature_c": value_c}))
        except InputError as exc:
            status = "BadOutOfRange" if exc.status_code == 422 else "BadInvalidState"
            return await answer(status, str(exc))
        # the variable then reads the measurement once the twin has taken it (the snapshot's
        # thermal block), as every other variable reads the snapshot
        return await answer("Good", node=node, temperature_c=value_c)
