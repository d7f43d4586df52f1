"""A client of obscurad, the ambient-occlusion daemon, in one file of the
Python standard library (no pip needed): copy it next to a script, or put
its folder on sys.path, in the Python of Nuke, Houdini, Maya or Blender.

    import obscura_client as oc
    exr = oc.ao("frame.exr", server="http://127.0.0.1:8420", radius=0.5)
    oc.ao("frame.exr", server="unix:/run/obscurad.sock", append=1, layer="occ",
          out="frame.ao.exr")

Servers: http://HOST:PORT (the HTTP API, POST /v1/ao, through http.client,
on which urllib.request runs), unix:/PATH and
tcp://HOST:PORT (the binary protocol, protocol/PROTOCOL.md).  Parameters
are the daemon's query parameters (GET /v1/params): the parameter table
(radius, samples, fov_y, world_to_camera, ...) and the request options
(output, format, float, png_bits, preset, depth, normal, color, layer,
append).  Values may be str, int, float, bool (1/0) or a list or tuple
(joined with commas: world_to_camera, normal, color).

A file is streamed to the daemon as it is read (never held whole in
memory), and with out= the answer is streamed into a file.  A refusal is
an ObscuraError whose .code is the daemon's JSON error code
("bad_parameter", "missing_channel", "no_camera", "queue_full", ...);
an unreachable daemon raises ObscuraError with code "unreachable".

The camera JSON that `obscura ao --camera` takes (written beside a render:
world_to_camera, projection or fov_y_deg, near, far) is sent with
camera=Camera.from_json(path or dict), as fov_y, near, far and
world_to_camera:

    cam = oc.Camera.from_json("frame.camera.json")
    exr = oc.ao("frame.exr", camera=cam, radius=0.5)

Warnings: the daemon's warnings on an answer (a wrong camera, AO near 1
everywhere: X-Obscura-Warning over HTTP, the answer's warnings over the
binary protocol; what `obscura ao` prints as "obscura: warning:") are
issued as ObscuraWarning through Python's warnings module, so a script
sees them by default (warnings.simplefilter("error", oc.ObscuraWarning)
makes them errors), and kept in the answer's .warnings (a list of str);
an ObscuraError has .warnings too.

Object masks (README: Object masks): receivers, occluders and self_only,
with selectors of Cryptomatte names (wildcards * and ?), integer IDs of a
channel or a coverage matte; selector() escapes names that hold ',', '*',
'?' or '\\' themselves:

    oc.ao("shot.exr", receivers=oc.selector("hero", "floor*", literal=False),
          occluders="id:IndexOB=3,5-7", self_only="on")

Level bakes (obscura bake on the daemon, POST /v1/bakes, HTTP only):

    oc.bake("level.glb", out="baked.glb", rays=64, distances=(2, 300))
    oc.bake("aalborg.acc", decorators="trees.json", out="baked.glb",
            progress=lambda done, stage: print(done, stage))

submit the level (and a decorators file, as multipart/form-data), wait for
the job while it reports its progress, and fetch the baked .glb; a job that
fails raises ObscuraError with the bake's status ("bad_file", "too_large",
...) as .code.

Works with Python 3.6 and later.
"""
import http.client
import json
import math
import os
import socket
import struct
import time
import urllib.parse
import warnings

__all__ = ["ao", "bake", "selector", "Answer", "Camera", "ObscuraError", "ObscuraWarning", "DEFAULT_SERVER"]
__version__ = "1.2.0"

DEFAULT_SERVER = "http://127.0.0.1:8420"
CHUNK = 1 << 16

# protocol/PROTOCOL.md: frame header and body kinds
MAGIC = b"OBSP"
VERSION = 1
KIND_REQUEST, KIND_RESPONSE = 1, 2
BODY_NONE, BODY_EXR, BODY_RAW, BODY_PNG = 0, 1, 2, 3
MAX_NAME, MAX_VALUE, MAX_PARAMS = 64, 4096, 256


class ObscuraError(Exception):
    """A request obscurad refused or could not answer.

    status: the HTTP status (the binary protocol uses the same numbers),
    None when the daemon was not reached; code: the JSON error code;
    message: what is wrong; retry_after: seconds to wait (503), or 0;
    warnings: the warnings the answer carried (a list of str, often
    empty: a refusal's reason is its message)."""

    def __init__(self, status, code, message, retry_after=0, warnings=None):
        Exception.__init__(self, "%s%s: %s" % (code, " (%d)" % status if status else "", message))
        self.status = status
        self.code = code
        self.message = message
        self.retry_after = retry_after
        self.warnings = list(warnings or [])


class ObscuraWarning(UserWarning):
    """A warning obscurad gave with its answer: the answer was computed,
    but likely not as meant (the text names the cause and the flag or
    parameter that fixes it)."""


class Answer(bytes):
    """What ao() returns: the answer's bytes (an EXR, or a PNG with
    format="png"; b"" when out= took them), and .warnings, the daemon's
    warnings on it (a list of str, [] when none)."""

    def __new__(cls, data, warnings_=None):
        self = bytes.__new__(cls, data)
        self.warnings = list(warnings_ or [])
        return self


def _warn(texts):
    # stacklevel 3: the line of the script that called ao()
    for t in texts:
        warnings.warn(t, ObscuraWarning, stacklevel=3)


def _f32(x):
    """x as the float32 the CLI's camera reader keeps."""
    return struct.unpack("<f", struct.pack("<f", float(x)))[0]


class Camera(object):
    """A camera for ao(camera=...): a vertical field of view in degrees,
    the clip range and the 4x4 world_to_camera (row-major, column-vector
    convention: p_cam = M p_world, the camera looking down -Z), sent as
    the query parameters fov_y, near, far and world_to_camera."""

    def __init__(self, fov_y, world_to_camera, near=0.1, far=1000.0):
        m = [float(v) for row in world_to_camera for v in (row if isinstance(row, (list, tuple)) else [row])]
        if len(m) != 16:
            raise ValueError("Camera: world_to_camera is 4 rows of 4 numbers (or 16 numbers), not %d numbers" % len(m))
        if not 0 < fov_y < 180:
            raise ValueError("Camera: fov_y %r is not degrees between 0 and 180" % (fov_y,))
        if not near > 0 or not far > near:
            raise ValueError("Camera: near %r and far %r: expected 0 < near < far" % (near, far))
        self.fov_y, self.near, self.far = float(fov_y), float(near), float(far)
        self.world_to_camera = m

    @classmethod
    def from_json(cls, source):
        """The camera of a camera JSON (what `obscura ao --camera` reads,
        core/camera/json.c): a path, or the dict json.load gives.  It has
        world_to_camera, and projection (a symmetric perspective) or
        fov_y_deg (with width and height); near and far default to 0.1 and
        1000.  The values are those the CLI reads (float32), written as
        the CLI sends them (remote.c), so that an answer is the CLI's."""
        what = "Camera.from_json()"
        if isinstance(source, (str, os.PathLike)):
            what = "Camera.from_json(%r)" % os.fspath(source)
            with open(source, "rb") as f:
                try:
                    source = json.loads(f.read().decode("utf-8"))
                except ValueError as e:
                    raise ValueError("%s: not valid JSON: %s" % (what, e))
        if not isinstance(source, dict):
            raise TypeError("%s takes a path or a dict, not %r" % (what, type(source)))

        def number(name, default=None):
            v = source.get(name, default)
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float)) or v != v):
                raise ValueError("%s: %s: expected a number" % (what, name))
            return v

        def mat4(name):
            v = source.get(name)
            if v is None:
                return None
            flat = v if isinstance(v, list) and len(v) == 16 else \
                [x for row in v for x in row] if isinstance(v, list) and len(v) == 4 and \
                all(isinstance(r, list) and len(r) == 4 for r in v) else None
            if flat is None or any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in flat):
                raise ValueError("%s: %s: expected 4 rows of 4 numbers" % (what, name))
            return [_f32(x) for x in flat]

        w2c, proj = mat4("world_to_camera"), mat4("projection")
        if w2c is None:
            raise ValueError("%s: world_to_camera: missing" % what)
        if proj is not None:
            p = proj
            if p[14] != -1 or p[15] != 0 or p[1] or p[2] or p[4] or p[6] or p[3] or p[7] or p[5] <= 0:
                raise ValueError("%s: projection: only a symmetric perspective projection can be sent "
                                 "(as fov_y, near, far)" % what)
            fov = 2.0 * math.atan(1.0 / p[5]) * 180.0 / math.pi
            near, far = p[11] / (p[10] - 1.0), p[11] / (p[10] + 1.0)
        else:
            fov = number("fov_y_deg")
            if fov is None or number("width") is None or number("height") is None:
                raise ValueError("%s: projection: missing (and no fov_y_deg with width and height to "
                                 "build one)" % what)
            near, far = _f32(number("near", 0.1)), _f32(number("far", 1000.0))
            fov = _f32(fov)
        return cls(fov, w2c, near, far)

    def params(self):
        """The query parameters: fov_y, near, far, world_to_camera."""
        return {"fov_y": "%.9g" % self.fov_y, "near": "%.9g" % self.near, "far": "%.9g" % self.far,
                "world_to_camera": ",".join("%.9g" % v for v in self.world_to_camera)}

    def __repr__(self):
        return "Camera(fov_y=%.6g, near=%.6g, far=%.6g)" % (self.fov_y, self.near, self.far)


def selector(*names, literal=True, layer=None):
    """A receivers/occluders selector of Cryptomatte names: joined with
    ',', each name's ',', '*', '?', '\\' (and a leading '@' or '!') escaped when
    literal, else * and ? kept as wildcards; layer: "@LAYER:" first (one
    Cryptomatte layer of the file instead of all)."""
    out = []
    for n in names:
        n = str(n)
        if literal:
            n = "".join("\\" + c if c in ",*?\\" else c for c in n)
        else:
            n = n.replace("\\", "\\\\").replace(",", "\\,")
        if n.startswith("@") or n.startswith("!"):
            n = "\\" + n
        out.append(n)
    return ("@%s:" % layer if layer else "") + ",".join(out)


# How True and False are spelt: a frame's switches (blur, self_only, ...)
# take on/off, as do its request options (float, append, ...); the bake's
# switches (lod_lock_border, ...) are integers 0/1.
_FRAME_BOOL = ("on", "off")
_BAKE_BOOL = ("1", "0")


def _value(v, words=_FRAME_BOOL):
    if isinstance(v, bool):
        return words[0] if v else words[1]
    if isinstance(v, (list, tuple)):
        return ",".join(_value(x, words) for x in v)
    if isinstance(v, float):
        return repr(v)
    return str(v)


def _params(params, token, words=_FRAME_BOOL):
    out = []
    for k, v in params.items():
        if v is None:
            continue
        out.append((str(k), _value(v, words)))
    if token:
        out.append(("token", token))
    return out


class _Source(object):
    """The EXR to send: a path (streamed), bytes, or a readable file
    object with a known size."""

    def __init__(self, source, what="ao(): the EXR"):
        self.f = None
        self.data = None
        if isinstance(source, (bytes, bytearray, memoryview)):
            self.data = bytes(source)
            self.size = len(self.data)
        elif isinstance(source, (str, os.PathLike)):
            self.f = open(source, "rb")
            self.size = os.fstat(self.f.fileno()).st_size
        elif hasattr(source, "read"):
            self.f = source
            pos = source.tell()
            source.seek(0, os.SEEK_END)
            self.size = source.tell() - pos
            source.seek(pos)
        else:
            raise TypeError("%s is a path, bytes or a binary file object, not %r" % (what, type(source)))
        if self.size == 0:
            raise ValueError("%s is empty" % what)

    def chunks(self):
        if self.data is not None:
            yield self.data
            return
        while True:
            b = self.f.read(CHUNK)
            if not b:
                return
            yield b

    def body(self):
        return self.data if self.data is not None else self.f

    def close(self, opened_here):
        if opened_here and self.f is not None:
            self.f.close()


class _Sink(object):
    """Where the answer goes: a file (path or object) or memory."""

    def __init__(self, out):
        self.parts = []
        self.f = None
        self.path = None
        if isinstance(out, (str, os.PathLike)):
            self.path = os.fspath(out)
            self.f = open(self.path + ".part", "wb")
        elif out is not None:
            self.f = out

    def write(self, b):
        if self.f is not None:
            self.f.write(b)
        else:
            self.parts.append(b)

    def done(self):
        if self.path is not None:
            self.f.close()
            os.replace(self.path + ".part", self.path)
            return None
        if self.f is not None:
            return None
        return b"".join(self.parts)

    def fail(self):
        if self.path is not None:
            self.f.close()
            try:
                os.unlink(self.path + ".part")
            except OSError:
                pass


def _http_error(status, body):
    try:
        e = json.loads(body.decode("utf-8", "replace"))["error"]
        return e.get("code", "error"), e.get("message", "")
    except (ValueError, KeyError, TypeError):
        return "http_%d" % status, body.decode("utf-8", "replace")[:500]


def _header_warnings(resp):
    """The X-Obscura-Warning headers, as the daemon wrote them (UTF-8;
    http.client reads header bytes as Latin-1)."""
    return [v.encode("latin-1", "replace").decode("utf-8", "replace")
            for v in (resp.msg.get_all("X-Obscura-Warning") or [])]


def _request(server, method, path, token, timeout, body=None, headers=None, sink=None):
    """One HTTP request; the status, the answer's body (None when it was
    streamed into sink) and its warnings.  body: None or a list of bytes and _Source
    pieces, sent in turn.  http.client (what urllib.request runs on)
    rather than urlopen: the daemon refuses a bad request before it reads
    the body and closes, and the answer must still be read after the send
    breaks off."""
    u = urllib.parse.urlsplit(server)
    conn = http.client.HTTPConnection(u.hostname or "127.0.0.1", u.port or 80, timeout=timeout)
    try:
        pieces = body or []
        size = sum(len(b) if isinstance(b, bytes) else b.size for b in pieces)
        try:
            conn.putrequest(method, (u.path.rstrip("/") or "") + path)
            for k, v in (headers or {}).items():
                conn.putheader(k, v)
            if body is not None:
                conn.putheader("Content-Length", str(size))
            if token:
                conn.putheader("Authorization", "Bearer " + token)
            conn.endheaders()
        except OSError as e:
            raise ObscuraError(None, "unreachable", "%s: %s" % (server, e))
        try:
            for b in pieces:
                for c in ([b] if isinstance(b, bytes) else b.chunks()):
                    conn.send(c)
        except (BrokenPipeError, ConnectionResetError):
            pass  # refused before the body was read: the answer says why
        try:
            resp = conn.getresponse()
        except (OSError, http.client.HTTPException) as e:
            raise ObscuraError(None, "unreachable", "%s: no answer: %s" % (server, e))
        said = _header_warnings(resp)
        if resp.status >= 300:
            code, msg = _http_error(resp.status, resp.read())
            retry = resp.getheader("Retry-After")
            raise ObscuraError(resp.status, code, msg, int(retry) if retry and retry.isdigit() else 0, said)
        if sink is None:
            return resp.status, resp.read(), said
        while True:
            b = resp.read(CHUNK)
            if not b:
                break
            sink.write(b)
        return resp.status, None, said
    except socket.timeout:
        raise ObscuraError(None, "unreachable", "%s: no answer within %s s" % (server, timeout))
    finally:
        conn.close()

def _ao_http(server, src, params, token, sink, timeout):
    return _request(server, "POST", "/v1/ao?" + urllib.parse.urlencode(params), token, timeout, [src],
                    {"Content-Type": "image/x-exr"}, sink)[2]


def _connect(server, timeout):
    try:
        if server.startswith("unix:"):
            s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            s.settimeout(timeout)
            s.connect(server[5:])
            return s
        host, _, port = server[len("tcp://"):].rpartition(":")
        host = host[1:-1] if host.startswith("[") else host
        return socket.create_connection((host or "127.0.0.1", int(port)), timeout=timeout)
    except (OSError, ValueError) as e:
        raise ObscuraError(None, "unreachable", "%s: %s" % (server, e))


def _recv_exact(s, n, server):
    buf = bytearray()
    while len(buf) < n:
        b = s.recv(min(n - len(buf), CHUNK))
        if not b:
            raise ObscuraError(None, "unreachable", "%s: the connection closed mid-answer" % server)
        buf += b
    return bytes(buf)


def _ao_binary(server, src, params, sink, timeout):
    # Request payload: parameters, kind 1 (EXR), padding to 8, the EXR's
    # length, then the EXR itself (sent as it is read).
    if len(params) > MAX_PARAMS:
        raise ValueError("ao(): at most %d parameters" % MAX_PARAMS)
    head = struct.pack("<I", len(params))
    for k, v in params:
        kb, vb = k.encode("utf-8"), v.encode("utf-8")
        if not 1 <= len(kb) <= MAX_NAME or len(vb) > MAX_VALUE:
            raise ValueError("ao(): parameter %r: the name is 1..%d bytes, the value at most %d" % (k, MAX_NAME, MAX_VALUE))
        head += struct.pack("<H", len(kb)) + kb + struct.pack("<I", len(vb)) + vb
    head += bytes([BODY_EXR])
    head += b"\0" * ((8 - len(head) % 8) % 8)
    head += struct.pack("<Q", src.size)
    frame_id = 1
    header = MAGIC + struct.pack("<HHQQ", VERSION, KIND_REQUEST, frame_id, len(head) + src.size)
    s = _connect(server, timeout)
    try:
        try:
            s.sendall(header + head)
            for b in src.chunks():
                s.sendall(b)
        except OSError:
            pass  # refused from the head: the answer says why
        h = _recv_exact(s, 24, server)
        magic, version, kind, rid, length = struct.unpack("<4sHHQQ", h)
        if magic != MAGIC or kind != KIND_RESPONSE or version != VERSION:
            raise ObscuraError(None, "bad_answer", "%s: not an obscurad binary-protocol answer" % server)
        off = 0
        status, retry, clen = struct.unpack("<HHH", _recv_exact(s, 6, server))
        code = _recv_exact(s, clen, server).decode("utf-8", "replace")
        (mlen,) = struct.unpack("<I", _recv_exact(s, 4, server))
        msg = _recv_exact(s, mlen, server).decode("utf-8", "replace")
        body = _recv_exact(s, 1, server)[0]
        off = 6 + clen + 4 + mlen + 1
        _recv_exact(s, (8 - off % 8) % 8, server)
        if status != 200:
            raise ObscuraError(status, code, msg, retry)
        # a 200's message holds the answer's warnings, one a line
        # (PROTOCOL.md, "Response payload"); older daemons send ""
        said = [w for w in msg.split("\n") if w]
        if body not in (BODY_EXR, BODY_PNG):
            raise ObscuraError(status, "bad_answer", "%s: answer body kind %d (ask format=exr or png)" % (server, body))
        (n,) = struct.unpack("<Q", _recv_exact(s, 8, server))
        while n > 0:
            b = s.recv(min(n, CHUNK))
            if not b:
                raise ObscuraError(None, "unreachable", "%s: the connection closed mid-answer" % server)
            sink.write(b)
            n -= len(b)
        return said
    except socket.timeout:
        raise ObscuraError(None, "unreachable", "%s: no answer within %s s" % (server, timeout))
    finally:
        s.close()


def ao(source, server=None, out=None, token=None, timeout=300, camera=None, **params):
    """The AO of one G-buffer EXR from obscurad.

    source: a path (streamed from disk), bytes, or a binary file object.
    server: http://HOST:PORT, unix:/PATH or tcp://HOST:PORT (default: the
    OBSCURA_SERVER environment variable, else http://127.0.0.1:8420).
    out: a path or a binary file object to stream the answer into (a
    path is written whole or not at all); then the Answer is b"".
    token: the bearer token (default: OBSCURA_TOKEN).
    camera: a Camera (Camera.from_json("frame.camera.json")), sent as
    fov_y, near, far and world_to_camera unless params give them.
    params: the daemon's query parameters (True/False are sent as on/off,
    which switches like blur and options like float both take).
    Returns an Answer: the answer's bytes (an EXR, or a PNG with
    format="png"; b"" with out=) and .warnings, the daemon's warnings,
    each also issued as an ObscuraWarning (Python's warnings module).
    Raises ObscuraError (with .code) when the daemon refuses or cannot
    be reached, TypeError/ValueError for arguments it cannot send."""
    server = server or os.environ.get("OBSCURA_SERVER") or DEFAULT_SERVER
    token = token if token is not None else os.environ.get("OBSCURA_TOKEN")
    if str(params.get("format", "exr")) == "raw":
        raise ValueError("ao(): format=raw is not an answer this client returns (use exr or png)")
    if camera is not None:
        if not isinstance(camera, Camera):
            raise TypeError("ao(): camera is a Camera (Camera.from_json), not %r" % type(camera))
        given = set(k.replace("-", "_") for k in params)
        params = dict([(k, v) for k, v in camera.params().items() if k not in given] + list(params.items()))
    opened_here = isinstance(source, (str, os.PathLike))
    src = _Source(source)
    sink = _Sink(out)
    try:
        if server.startswith("http://"):
            said = _ao_http(server, src, _params(params, None), token, sink, timeout)
        elif server.startswith("unix:") or server.startswith("tcp://"):
            said = _ao_binary(server, src, _params(params, token), sink, timeout)
        else:
            raise ValueError("ao(): server %r is not http://HOST:PORT, unix:/PATH or tcp://HOST:PORT" % server)
    except BaseException:
        sink.fail()
        raise
    finally:
        src.close(opened_here)
    data = sink.done()
    _warn(said)
    return Answer(data if data is not None else b"", said)


# ---- bake jobs (POST /v1/bakes, protocol/HTTP.md "Bake jobs") ----------

def _multipart(level, decorators):
    """The body parts of a multipart/form-data POST: level and decorators."""
    boundary = "obscura-" + os.urandom(12).hex()

    def head(name):
        return ("--%s\r\nContent-Disposition: form-data; name=\"%s\"; filename=\"%s\"\r\n"
                "Content-Type: application/octet-stream\r\n\r\n" % (boundary, name, name)).encode()
    body = [head("level"), level, b"\r\n", head("decorators"), decorators,
            ("\r\n--%s--\r\n" % boundary).encode()]
    return body, "multipart/form-data; boundary=" + boundary


def bake(level, server=None, out=None, token=None, decorators=None, timeout=60,
         poll=0.5, progress=None, **params):
    """A level baked by obscurad (POST /v1/bakes): per-vertex ambient
    obscurance into a .glb.

    level: a path (streamed), bytes, or a binary file object; its format
    is told from its first bytes unless format="EXT" says it.
    decorators: a decorators file (path, bytes or file object), as
    obscura bake --decorators takes it; sent beside the level.
    server: http://HOST:PORT (default OBSCURA_SERVER, else
    http://127.0.0.1:8420); token: the bearer token (default OBSCURA_TOKEN).
    out: a path or binary file object for the .glb (then None is
    returned); timeout: seconds for each request, not for the bake;
    poll: seconds between looks at the job; progress(done, stage): called
    on each look, done the share of samples traced.
    params: the bake parameters (obscura bake --params), distances=(S, L).
    Returns the .glb's bytes.  Raises ObscuraError: the daemon's refusal,
    or the job's failure (.code its status, e.g. "bad_file")."""
    server = server or os.environ.get("OBSCURA_SERVER") or DEFAULT_SERVER
    token = token if token is not None else os.environ.get("OBSCURA_TOKEN")
    if not server.startswith("http://"):
        raise ValueError("bake(): bake jobs are HTTP routes: server %r is not http://HOST:PORT" % server)
    opened = [x for x in (level, decorators) if isinstance(x, (str, os.PathLike))]
    src = _Source(level, "bake(): the level")
    dec = _Source(decorators, "bake(): the decorators file") if decorators is not None else None
    query = "/v1/bakes?" + urllib.parse.urlencode(_params(params, None, _BAKE_BOOL))
    try:
        if dec is None:
            body, ctype = [src], "application/octet-stream"
        else:
            body, ctype = _multipart(src, dec)
        _, answer, _ = _request(server, "POST", query, token, timeout, body, {"Content-Type": ctype})
    finally:
        src.close(level in opened)
        if dec is not None:
            dec.close(decorators in opened)
    job = json.loads(answer.decode("utf-8"))
    jid = job["id"]
    while True:
        _, answer, _ = _request(server, "GET", "/v1/bakes/" + jid, token, timeout)
        job = json.loads(answer.decode("utf-8"))
        if progress is not None:
            progress(job.get("progress", 0), job.get("stage", ""))
        if job["state"] == "done":
            break
        if job["state"] in ("failed", "cancelled"):
            e = job.get("error", {})
            raise ObscuraError(None, str(e.get("status", job["state"])).lower(),
                               e.get("message", "the bake job ended " + job["state"]))
        time.sleep(poll)
    sink = _Sink(out)
    try:
        _request(server, "GET", "/v1/bakes/%s/result" % jid, token, timeout, sink=sink)
    except BaseException:
        sink.fail()
        raise
    return sink.done()
