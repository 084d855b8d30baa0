"""The OPC UA facade of the service (asyncua): one object per twin, setpoints writable through the
same admission gate and limits as HTTP, alarms as events. Off by default (`serve --opcua
opc.tcp://127.0.0.1:4840`). Address space: service.opcua.layout; server: service.opcua.server;
security policies, certificates, trusted clients: service.opcua.security; docs/service.md "OPC UA"."""

from service.opcua.layout import EVENT_TYPE, NAMESPACE_URI, ROOT_FOLDER
from service.opcua.server import OpcUaError, OpcUaFacade

__all__ = ["EVENT_TYPE", "NAMESPACE_URI", "ROOT_FOLDER", "OpcUaError", "OpcUaFacade"]
