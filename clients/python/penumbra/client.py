"""penumbra.Client: the render service's HTTP API (docs/http-api.md) from Python, standard
library only."""
from __future__ import annotations

import http.client
import json
import os
import shutil
import sys
import time
from typing import Any, Callable, Dict, Iterator, List, Mapping, Optional, Union
from urllib.parse import quote, urlencode, urlsplit

from . import assets as _assets
from .errors import ConnectionFailed, JobFailed, PenumbraError, problem_error

JobRef = Union[str, Mapping[str, Any]]
Progress = Union[bool, Callable[[Dict[str, Any]], None]]

FINAL_STATES = ("succeeded", "failed", "cancelled")


def _job_id(job: JobRef) -> str:
    if isinstance(job, Mapping):
        job = str(job.get("id", ""))
    job = job.rsplit("/", 1)[-1] if job.startswith("/") else job
    if not job:
        raise ValueError("no job id")
    return job


class _Response:
    def __init__(self, status: int, headers: http.client.HTTPMessage, body: bytes):
        self.status, self.headers, self.body = status, headers, body

    def json(self) -> Any:
        return json.loads(self.body.decode("utf-8"))


class Client:
    """A connection to a `penumbra serve`.

    `url` defaults to $PENUMBRA_URL, else http://127.0.0.1:8080; `token` to $PENUMBRA_TOKEN (sent
    as `Authorization: Bearer`). `timeout` bounds each network wait, in seconds.
    """

    def __init__(self, url: Optional[str] = None, token: Optional[str] = None,
                 timeout: float = 60.0):
        self.url = (url or os.environ.get("PENUMBRA_URL") or "http://127.0.0.1:8080").rstrip("/")
        self.token = token if token is not None else os.environ.get("PENUMBRA_TOKEN") or None
        self.timeout = timeout
        parts = urlsplit(self.url)
        if parts.scheme not in ("http", "https") or not parts.hostname:
            raise ValueError(f"not an http(s) URL: {self.url!r}")
        self._https = parts.scheme == "https"
        self._host = parts.hostname
        self._port = parts.port
        self._prefix = parts.path.rstrip("/")
        #: bytes of asset data sent by this client (uploads), for measuring de-duplication
        self.bytes_uploaded = 0

    # -- transport -------------------------------------------------------------------------------
    def _connection(self, timeout: Optional[float] = None) -> http.client.HTTPConnection:
        cls = http.client.HTTPSConnection if self._https else http.client.HTTPConnection
        return cls(self._host, self._port, timeout=timeout or self.timeout)

    def _headers(self, extra: Optional[Mapping[str, str]] = None) -> Dict[str, str]:
        h = {"User-Agent": "penumbra-client-python/0.2"}
        if self.token:
            h["Authorization"] = f"Bearer {self.token}"
        if extra:
            h.update(extra)
        return h

    def _open(self, method: str, path: str, body: Any = None,
              headers: Optional[Mapping[str, str]] = None, timeout: Optional[float] = None):
        conn = self._connection(timeout)
        try:
            conn.request(method, self._prefix + path, body=body, headers=self._headers(headers))
            return conn, conn.getresponse()
        except (OSError, http.client.HTTPException) as e:
            conn.close()
            raise ConnectionFailed(f"{method} {self.url}{path}: {e}") from None

    def _request(self, method: str, path: str, body: Any = None,
                 headers: Optional[Mapping[str, str]] = None, ok=(200, 201, 202, 204)) -> _Response:
        conn, resp = self._open(method, path, body, headers)
        try:
            data = resp.read()
        except (OSError, http.client.HTTPException) as e:
            raise ConnectionFailed(f"{method} {self.url}{path}: {e}") from None
        finally:
            conn.close()
        if resp.status not in ok:
            raise problem_error(resp.status, data, resp.getheader("Content-Type", ""),
                                resp.getheader("Retry-After"))
        return _Response(resp.status, resp.headers, data)

    def _json(self, method: str, path: str, payload: Any = None, **kw) -> Any:
        body = None if payload is None else json.dumps(payload).encode("utf-8")
        headers = {"Accept": "application/json"}
        if body is not None:
            headers["Content-Type"] = "application/json"
        headers.update(kw.pop("headers", {}) or {})
        return self._request(method, path, body, headers, **kw).json()

    # -- service ---------------------------------------------------------------------------------
    def health(self) -> bool:
        """True when /readyz says the service takes jobs."""
        try:
            self._request("GET", "/readyz")
            return True
        except PenumbraError:
            return False

    # -- assets ----------------------------------------------------------------------------------
    def missing_assets(self, hashes) -> list:
        """The hashes ("sha256:...") the server does not have."""
        return list(self._json("POST", "/v1/assets/missing", {"hashes": list(hashes)})["missing"])

    def upload_assets(self, files: Mapping[str, _assets.AssetSource]) -> Dict[str, str]:
        """Makes sure the server has every file ({name: path or bytes}); uploads only those it
        lacks. Returns the manifest {name: "sha256:..."}."""
        listed = _assets.manifest(files)
        missing = set(self.missing_assets(sorted(set(listed.values()))))
        sent = set()
        for name, digest in listed.items():
            if digest not in missing or digest in sent:
                continue
            self._put_asset(digest, files[name])
            sent.add(digest)
        return listed

    def _put_asset(self, digest: str, source: _assets.AssetSource) -> None:
        path = "/v1/assets/" + digest.split(":", 1)[1]
        headers = {"Content-Type": "application/octet-stream"}
        if isinstance(source, (bytes, bytearray, memoryview)):
            self._request("PUT", path, bytes(source), headers)
            self.bytes_uploaded += len(source)
            return
        size = os.path.getsize(source)
        headers["Content-Length"] = str(size)
        with open(source, "rb") as f:
            self._request("PUT", path, f, headers)
        self.bytes_uploaded += size

    # -- jobs ------------------------------------------------------------------------------------
    def submit(self, scene: Union[Mapping[str, Any], str, os.PathLike],
               assets: Optional[Mapping[str, _assets.AssetSource]] = None, *,
               base_dir: Optional[Union[str, os.PathLike]] = None,
               priority: Optional[int] = None, notify: Optional[Mapping[str, str]] = None,
               idempotency_key: Optional[str] = None,
               params: Optional[Mapping[str, Any]] = None) -> Dict[str, Any]:
        """Submits a render job and returns its record (a dict with "id" and "state").

        `scene` is a scene dict, a path to a scene .json, or a path to a .glb (rendered as
        `penumbra render model.glb` would; `params` such as width, height, spp become query
        parameters). The files the scene names are found under `base_dir` (default: the scene
        file's folder) and uploaded if the server lacks them; `assets` adds or overrides
        {name: path or bytes}.
        """
        if isinstance(scene, (str, os.PathLike)):
            path = os.fspath(scene)
            if path.lower().endswith(".glb"):
                return self._submit_glb(path, params, priority, idempotency_key)
            with open(path, "rb") as f:
                scene = json.loads(f.read().decode("utf-8"))
            if base_dir is None:
                base_dir = os.path.dirname(os.path.abspath(path))
        files: Dict[str, _assets.AssetSource] = {}
        if base_dir is not None:
            files.update(_assets.scene_files(scene, base_dir))
        if assets:
            files.update(assets)
        body: Dict[str, Any]
        if files:
            body = {"scene": scene, "assets": self.upload_assets(files)}
        else:
            body = dict(scene)
        extra = {}
        if priority is not None:
            extra["priority"] = priority
        if notify is not None:
            extra["notify"] = dict(notify)
        if extra:
            body = body if files else {"scene": body}
            body.update(extra)
        headers = {"Idempotency-Key": idempotency_key} if idempotency_key else {}
        query = "?" + urlencode(params) if params else ""
        return self._json("POST", "/v1/jobs" + query, body, headers=headers)

    def _submit_glb(self, path, params, priority, idempotency_key) -> Dict[str, Any]:
        query = dict(params or {})
        if priority is not None:
            query["priority"] = priority
        headers = {"Content-Type": "model/gltf-binary", "Accept": "application/json",
                   "Content-Length": str(os.path.getsize(path))}
        if idempotency_key:
            headers["Idempotency-Key"] = idempotency_key
        with open(path, "rb") as f:
            resp = self._request("POST", "/v1/jobs" + ("?" + urlencode(query) if query else ""),
                                 f, headers)
        return resp.json()

    def job(self, job: JobRef) -> Dict[str, Any]:
        """The job's current record."""
        return self._json("GET", "/v1/jobs/" + quote(_job_id(job)))

    def list(self, state: Optional[str] = None, limit: int = 100) -> Iterator[Dict[str, Any]]:
        """Every job (newest first; queued jobs in run order with state="queued"), page by page."""
        token = None
        while True:
            query = {"limit": limit}
            if state:
                query["state"] = state
            if token:
                query["page_token"] = token
            page = self._json("GET", "/v1/jobs?" + urlencode(query))
            yield from page.get("jobs", [])
            token = page.get("next_page_token")
            if not token:
                return

    def cancel(self, job: JobRef) -> Dict[str, Any]:
        """Cancels a queued or running job (a finished one is deleted); returns its record."""
        resp = self._request("DELETE", "/v1/jobs/" + quote(_job_id(job)),
                             headers={"Accept": "application/json"})
        return resp.json() if resp.body else {"id": _job_id(job), "state": "deleted"}

    def wait(self, job: JobRef, progress: Progress = True, timeout: Optional[float] = None,
             check: bool = True) -> Dict[str, Any]:
        """Waits for the job's final state and returns its record. Follows the server's event
        stream (GET /v1/jobs/{id}/events, resuming with Last-Event-ID after a dropped connection),
        or polls where the server has none. `progress`: True draws a bar on a terminal's stderr, a
        callable gets each record. `check`: raise JobFailed if it failed or was cancelled."""
        job_id = _job_id(job)
        report = _progress_reporter(progress)
        deadline = None if timeout is None else time.monotonic() + timeout
        try:
            record = self._follow_events(job_id, report, deadline)
            if record is None:
                record = self._poll(job_id, report, deadline)
        finally:
            report(None)
        if check and record.get("state") != "succeeded":
            raise JobFailed(record)
        return record

    def _follow_events(self, job_id, report, deadline) -> Optional[Dict[str, Any]]:
        last_id = None
        failures = 0
        while failures < 5:
            if deadline is not None and time.monotonic() > deadline:
                raise TimeoutError(f"job {job_id} not finished in time")
            headers = {"Accept": "text/event-stream"}
            if last_id is not None:
                headers["Last-Event-ID"] = last_id
            try:
                conn, resp = self._open("GET", f"/v1/jobs/{quote(job_id)}/events", None, headers,
                                        timeout=max(self.timeout, 30.0))
            except ConnectionFailed:
                failures += 1
                time.sleep(0.5)
                continue
            try:
                if resp.status != 200 or "text/event-stream" not in \
                        (resp.getheader("Content-Type") or ""):
                    body = resp.read()
                    if resp.status in (401, 403):
                        raise problem_error(resp.status, body, resp.getheader("Content-Type", ""))
                    # No event stream here (an older server, or no such job): polling says
                    # which, with the right error.
                    return None
                for event_id, data in _sse_events(resp):
                    if event_id is not None:
                        last_id = event_id
                    try:
                        record = json.loads(data)
                    except ValueError:
                        continue
                    if not isinstance(record, dict):
                        continue
                    report(record)
                    if record.get("state") in FINAL_STATES:
                        return record
                    if deadline is not None and time.monotonic() > deadline:
                        raise TimeoutError(f"job {job_id} not finished in time")
                failures += 1  # the stream ended without a final state: resume
            except (OSError, http.client.HTTPException):
                failures += 1
            finally:
                conn.close()
        return None

    def _poll(self, job_id, report, deadline) -> Dict[str, Any]:
        delay = 0.2
        while True:
            record = self.job(job_id)
            report(record)
            if record.get("state") in FINAL_STATES:
                return record
            if deadline is not None and time.monotonic() > deadline:
                raise TimeoutError(f"job {job_id} not finished in time")
            time.sleep(delay)
            delay = min(delay * 1.5, 2.0)

    def result(self, job: JobRef, format: str = "exr", layer: Optional[str] = None,
               as_array: Optional[bool] = None, layout: Optional[str] = None,
               preview: bool = False, frame: Optional[int] = None):
        """The job's image: bytes of the PNG or EXR, or (EXR, when numpy is installed and
        `as_array` is not False) a float32 array of shape (height, width, channels).
        `preview=True`: the progressive image of a running job (a ProblemError with status 409
        until its first pass is done). `frame`: one frame of an animation job, available as soon
        as it is finished (a ProblemError with status 404 naming `frame` before, or outside the
        animation's frames; 422 for a still)."""
        query: Dict[str, str] = {"format": format}
        if frame is not None:
            query["frame"] = str(int(frame))
        if preview:
            query["preview"] = "true"
        if layer:
            query["layer"] = layer
        if layout:
            query["layout"] = layout
        data = self._request("GET", f"/v1/jobs/{quote(_job_id(job))}/result?" + urlencode(query),
                             headers={"Accept": "image/png" if format == "png" else "image/x-exr"}
                             ).body
        if as_array is False or format != "exr":
            if as_array:
                raise ValueError("arrays come from EXR results (format='exr')")
            return data
        try:
            import numpy  # noqa: F401
        except ImportError:
            if as_array:
                raise
            return data
        from .exr import read_exr, rgb

        planes = read_exr(data)
        if layout:
            return planes
        if layer and not any(k.startswith(layer + ".") for k in planes):
            return rgb(planes)  # a separate layer download has plain channel names
        return rgb(planes, layer or "")

    def frames_archive(self, job: JobRef, dest, format: str = "exr",
                       layer: Optional[str] = None, layout: Optional[str] = None) -> int:
        """Streams the animation job's frames archive (GET /v1/jobs/{id}/frames.tar: a tar of
        frame_0001.exr ...) into `dest` (a path or a binary file object), 1 MiB at a time, never
        whole in memory. Returns the bytes written."""
        query: Dict[str, str] = {"format": format}
        if layer:
            query["layer"] = layer
        if layout:
            query["layout"] = layout
        path = f"/v1/jobs/{quote(_job_id(job))}/frames.tar?" + urlencode(query)
        conn, resp = self._open("GET", path, headers={"Accept": "application/x-tar"})
        try:
            if resp.status != 200:
                data = resp.read()
                raise problem_error(resp.status, data, resp.getheader("Content-Type", ""),
                                    resp.getheader("Retry-After"))
            expected = resp.getheader("Content-Length")
            out = open(dest, "wb") if isinstance(dest, (str, os.PathLike)) else dest
            written = 0
            try:
                while True:
                    chunk = resp.read(1 << 20)
                    if not chunk:
                        break
                    out.write(chunk)
                    written += len(chunk)
            finally:
                if out is not dest:
                    out.close()
        except (OSError, http.client.HTTPException) as e:
            raise ConnectionFailed(f"GET {self.url}{path}: {e}") from None
        finally:
            conn.close()
        if expected is not None and written != int(expected):
            raise ConnectionFailed(f"GET {self.url}{path}: the archive was cut short "
                                   f"({written} of {expected} bytes)")
        return written

    def download_frames(self, job: JobRef, directory, format: str = "exr",
                        layer: Optional[str] = None, layout: Optional[str] = None) -> List[str]:
        """Every finished frame of an animation job as files in `directory` (made if missing):
        frame_0001.exr, frame_0002.exr ... as in the archive, streamed through a temporary file
        and extracted (no member may leave the directory). Returns the paths, in frame order."""
        import tarfile
        import tempfile

        os.makedirs(directory, exist_ok=True)
        with tempfile.TemporaryFile(dir=directory) as tmp:
            self.frames_archive(job, tmp, format=format, layer=layer, layout=layout)
            tmp.seek(0)
            paths = []
            with tarfile.open(fileobj=tmp, mode="r:") as tar:
                for member in tar:
                    name = member.name
                    if (not member.isfile() or "/" in name or "\\" in name or
                            name in ("", ".", "..")):
                        raise ValueError(f"unexpected archive member {name!r}")
                    target = os.path.join(directory, name)
                    with tar.extractfile(member) as src, open(target, "wb") as dst:
                        shutil.copyfileobj(src, dst, 1 << 20)
                    paths.append(target)
        return paths

    def render(self, scene, assets=None, format: str = "exr", progress: Progress = True,
               **submit_args):
        """submit, wait, result: the image of one scene (see result for its type)."""
        job = self.submit(scene, assets, **submit_args)
        self.wait(job, progress=progress)
        return self.result(job, format=format)


def _sse_events(resp) -> Iterator[tuple]:
    """(id, data) of each event of a text/event-stream (the WHATWG HTML "server-sent events"
    format: fields up to a blank line; comment lines start with ':')."""
    event_id, data = None, []
    while True:
        line = resp.readline()
        if not line:
            return
        line = line.decode("utf-8", "replace").rstrip("\r\n")
        if not line:
            if data:
                yield event_id, "\n".join(data)
            data = []
            continue
        if line.startswith(":"):
            continue
        name, _, value = line.partition(":")
        value = value[1:] if value.startswith(" ") else value
        if name == "data":
            data.append(value)
        elif name == "id":
            event_id = value


def _progress_reporter(progress: Progress) -> Callable[[Optional[Dict[str, Any]]], None]:
    if callable(progress):
        return lambda record: record is not None and progress(record)
    if not progress or not sys.stderr.isatty():
        return lambda record: None
    drawn = [False]

    def draw(record):
        if record is None:
            if drawn[0]:
                sys.stderr.write("\n")
            return
        fraction = float(record.get("progress") or 0.0)
        filled = int(round(30 * fraction))
        eta = record.get("eta_seconds")
        text = f"\r{record.get('id', '')[:8]} [{'#' * filled}{' ' * (30 - filled)}] " \
               f"{100 * fraction:5.1f}% {record.get('state', '')}"
        if isinstance(eta, (int, float)) and record.get("state") == "running":
            text += f" ETA {eta:.0f} s"
        sys.stderr.write(text + "   ")
        sys.stderr.flush()
        drawn[0] = True

    return draw


__all__ = ["Client", "FINAL_STATES"]
