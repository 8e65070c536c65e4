"""Errors of the penumbra client: what the server said (its RFC 9457 problem+json), typed."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional


class PenumbraError(Exception):
    """Anything the client reports: a refused request, an unreachable server, a failed job."""


class ConnectionFailed(PenumbraError):
    """The server could not be reached (refused, reset, timed out)."""


@dataclass
class FieldError:
    """One problem with a field of the submitted scene or request: `pointer` is its RFC 6901 JSON
    pointer ("/objects/3/radius"; "" for the whole document)."""

    pointer: str
    detail: str

    def __str__(self) -> str:
        return f"{self.pointer or '(document)'}: {self.detail}"


@dataclass
class ProblemError(PenumbraError):
    """The server answered with an error status. `problem` is its problem+json body (type, title,
    status, detail and any extensions) when it sent one."""

    status: int
    title: str = ""
    detail: str = ""
    type: str = ""
    problem: Dict[str, Any] = field(default_factory=dict)
    retry_after: Optional[float] = None

    def __post_init__(self) -> None:
        super().__init__(str(self))

    @property
    def errors(self) -> List[FieldError]:
        """The field errors the server listed (invalid scenes, manifests, parameters)."""
        out = []
        for e in self.problem.get("errors", []) or []:
            if isinstance(e, dict):
                out.append(FieldError(str(e.get("pointer", "")), str(e.get("detail", ""))))
        return out

    def __str__(self) -> str:
        text = f"HTTP {self.status}"
        if self.title:
            text += f" {self.title}"
        if self.detail:
            text += f": {self.detail}"
        for e in self.errors:
            text += f"\n  {e}"
        return text


class Unauthorized(ProblemError):
    """401/403: no token, or the wrong one."""


class NotFound(ProblemError):
    """404: no such job, result, layer or asset."""


class InvalidRequest(ProblemError):
    """400/422: the scene, manifest or a parameter is invalid; `errors` names each field."""


class Busy(ProblemError):
    """429/503/507: the server cannot take this now; `retry_after` says when to try again."""


class JobFailed(PenumbraError):
    """A job ended failed or cancelled. `job` is its last JSON record."""

    def __init__(self, job: Dict[str, Any]):
        self.job = job
        state = job.get("state", "?")
        reason = ""
        error = job.get("error")
        if isinstance(error, dict):
            reason = error.get("detail") or error.get("title") or ""
        super().__init__(f"job {job.get('id', '?')} {state}" + (f": {reason}" if reason else ""))


def problem_error(status: int, body: bytes, content_type: str,
                  retry_after: Optional[str] = None) -> ProblemError:
    """The typed error for an error answer."""
    import json

    problem: Dict[str, Any] = {}
    if "json" in (content_type or ""):
        try:
            parsed = json.loads(body.decode("utf-8"))
            if isinstance(parsed, dict):
                problem = parsed
        except (ValueError, UnicodeDecodeError):
            pass
    if status in (401, 403):
        cls = Unauthorized
    elif status == 404:
        cls = NotFound
    elif status in (400, 409, 413, 415, 422, 431):
        cls = InvalidRequest
    elif status in (429, 503, 507):
        cls = Busy
    else:
        cls = ProblemError
    delay = None
    if retry_after:
        try:
            delay = float(retry_after)
        except ValueError:
            delay = None
    detail = str(problem.get("detail", "")) if problem else body[:200].decode("utf-8", "replace")
    return cls(status=status, title=str(problem.get("title", "")), detail=detail,
               type=str(problem.get("type", "")), problem=problem, retry_after=delay)
