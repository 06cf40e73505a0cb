"""Clients and roles of a console :class:`oceangnc.console.session.Session`: one operator, any viewers."""

from __future__ import annotations

from .messages import Pause, Rejected


class ClientsMixin:
    """Pages and scripts attach as operator (commands) or viewer (watch only); control is taken over
    explicitly (``force``) and every change is an event."""

    def attach(self, want_control: bool = True) -> tuple[int, str]:
        """A page or script connected: returns ``(client id, role)``. It becomes the operator when it
        asks for control and nobody holds it; otherwise a viewer (watches, cannot command)."""
        with self._lock:
            self._next_client += 1
            cid = self._next_client
            self.clients += 1
            role = "viewer"
            if want_control and self.operator is None:
                self.operator = cid
                role = "operator"
            first = role == "operator" and self._await_operator
            if first:
                self._await_operator = False
        self.event("info", f"client #{cid} connected as {role} ({self.clients} client(s))")
        if first:
            self._cmds.append(Pause(type="pause", paused=False))
        return cid, role

    def detach(self, cid: int) -> None:
        """A client left; when it was the operator, nobody holds control (remote mode: failsafe)."""
        with self._lock:
            self.clients = max(0, self.clients - 1)
            was_op = self.operator == cid
            if was_op:
                self.operator = None
        if was_op:
            self.event("warning", f"operator #{cid} disconnected ({self.clients} client(s) left); nobody holds control")
        else:
            self.event("info", f"viewer #{cid} disconnected ({self.clients} client(s) left)")

    def take_control(self, cid: int, force: bool = False) -> None:
        """Client ``cid`` asks for control; taking it from another operator needs ``force`` (an
        explicit take-over, logged with both ids). Raises :class:`Rejected` otherwise."""
        with self._lock:
            cur = self.operator
            if cur == cid:
                return
            if cur is not None and not force:
                raise Rejected(f"control: operator #{cur} holds control; send force=true to take it over")
            self.operator = cid
            first = self._await_operator
            self._await_operator = False
        if cur is None:
            self.event("info", f"client #{cid} took control (operator)")
        else:
            self.event("alarm", f"TAKE-OVER: client #{cid} took control from operator #{cur}")
        if first:
            self._cmds.append(Pause(type="pause", paused=False))

    def release_control(self, cid: int) -> None:
        with self._lock:
            if self.operator != cid:
                return
            self.operator = None
        self.event("info", f"operator #{cid} released control")

    def role(self, cid: int) -> str:
        return "operator" if self.operator == cid else "viewer"

    def client_connected(self) -> int:
        """Legacy helper (tests, scripts): attach as operator; returns the client id."""
        cid, _ = self.attach(True)
        if self.operator != cid:
            self.take_control(cid, force=True)
        return cid

    def client_disconnected(self, cid: int | None = None) -> None:
        """Legacy helper: detach ``cid`` (default: the operator)."""
        self.detach(self.operator if cid is None else cid)
