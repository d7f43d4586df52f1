"""Misbehaving binary-protocol clients for tests/e2e/hostile_binary.sh.

    python3 binclient.py MODE TARGET [ARGS...]

TARGET is unix:/PATH, HOST:PORT or [V6-HOST]:PORT.  Every mode prints one
line of key=value results and never waits longer than its own bounds; the
frames are raw depth planes (protocol/PROTOCOL.md), camera fov_y=50.

  stall TARGET W H              a W x H format=raw frame, a 4 KiB receive
                                buffer; prints `stuck` once the answer
                                starts, then never reads (until killed, at
                                most 60 s)
  pipeline TARGET PID TOKEN     frames two at a time; after 3 answers sends
                                SIGTERM to PID, then counts the 200s, until
                                another answer, EOF or 15 s
  oversized TARGET PID TOKEN    a 200 MB frame (5000 x 10000) with TOKEN
                                ('-': none); sends the head, then streams
                                the planes while watching for an answer;
                                prints the status and PID's peak RSS growth
  headonly TARGET W H TOKEN     only the head of a W x H frame; the answer
                                within 5 s (or `timeout`), then EOF or not
  busy TARGET W H               keeps the GL worker busy with W x H frames
                                from 3 feeders while a prober sends heads
                                only; prints the first prober answer
  conns TARGET N [SRC,...]      opens N idle connections (for TCP from the
                                addresses SRC in turn), then what each got
                                within 3 s: open (nothing), an error
                                frame, EOF
  one TARGET                    one small frame; its status
"""
import os
import select
import signal
import socket
import struct
import sys
import threading
import time


def connect(target, rcvbuf=0, src=None):
    if target.startswith("unix:"):
        s = socket.socket(socket.AF_UNIX)
        s.connect(target[5:])
        return s
    host, port = target.rsplit(":", 1)
    fam = socket.AF_INET
    if host.startswith("["):
        host, fam = host[1:-1], socket.AF_INET6
    s = socket.socket(fam)
    if rcvbuf:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
    if src:
        s.bind((src, 0))
    s.connect((host, int(port)))
    return s


def head(w, h, params, fid, planes_len=None):
    """The header and the head of a raw depth frame; the planes' bytes
    are planes_len (default W x H float32) and are not included."""
    p = struct.pack("<I", len(params))
    for k, v in params:
        p += struct.pack("<H", len(k)) + k.encode() + struct.pack("<I", len(v)) + v.encode()
    p += b"\x02"
    p += b"\0" * ((8 - len(p) % 8) % 8)
    p += struct.pack("<IIiiiiII", w, h, 0, 0, 0, 0, 0, 0) + b"\0" * 128
    n = w * h * 4 if planes_len is None else planes_len
    return b"OBSP" + struct.pack("<HHQQ", 1, 1, fid, len(p) + n) + p


def frame(w, h, params, fid):
    depth = struct.pack("<f", 2.0) * (w * h)
    return head(w, h, params, fid) + depth


PENDING = {}  # bytes read past an answer, per socket


def read_answer(s, timeout):
    """(id, status, code) of the next answer, 'EOF' or 'timeout'."""
    s.settimeout(timeout)
    buf = PENDING.pop(s.fileno(), b"")
    try:
        while len(buf) < 24 or len(buf) < 24 + struct.unpack_from("<Q", buf, 16)[0]:
            b = s.recv(1 << 20)
            if not b:
                return "EOF"
            buf += b
    except socket.timeout:
        PENDING[s.fileno()] = buf
        return "timeout"
    except OSError:
        return "EOF"
    n = 24 + struct.unpack_from("<Q", buf, 16)[0]
    PENDING[s.fileno()] = buf[n:]
    fid, = struct.unpack_from("<Q", buf, 8)
    status, _, cl = struct.unpack_from("<HHH", buf, 24)
    return fid, status, buf[30:30 + cl].decode()


def eof_within(s, timeout):
    s.settimeout(timeout)
    try:
        while True:
            b = s.recv(65536)
            if not b:
                return True
    except socket.timeout:
        return False
    except OSError:
        return True


def params_with(token):
    p = [("fov_y", "50")]
    if token and token != "-":
        p.append(("token", token))
    return p


def hwm_kb(pid):
    with open("/proc/%s/status" % pid) as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    return 0


def stall(target, w, h):
    s = connect(target, rcvbuf=4096)
    s.sendall(frame(int(w), int(h), [("fov_y", "50"), ("format", "raw")], 1))
    # the answer has begun when a byte can be peeked; then read no more
    s.settimeout(60)
    s.recv(1, socket.MSG_PEEK)
    print("stuck", flush=True)
    time.sleep(60)


def pipeline(target, pid, token):
    w = h = 32
    s = connect(target)
    params = params_with(token)
    sent = answered = after = 0
    signalled = None
    last = ""
    t_end = time.time() + 30
    s.sendall(frame(w, h, params, 1) + frame(w, h, params, 2))
    sent = 2
    while time.time() < t_end:
        a = read_answer(s, 10)
        if not isinstance(a, tuple):
            last = a
            break
        answered += 1
        if a[1] != 200:
            last = "%d:%s" % (a[1], a[2])
            break
        if signalled is not None:
            after += 1
            if time.time() > signalled + 15:
                last = "still-serving"
                break
        if answered == 3:
            os.kill(int(pid), signal.SIGTERM)
            signalled = time.time()
        try:
            sent += 1
            s.sendall(frame(w, h, params, sent))
        except OSError:
            pass
    eof = eof_within(s, 5) if last not in ("EOF", "still-serving") else last == "EOF"
    print("after_sigterm_200=%d last=%s eof=%d" % (after, last or "none", int(eof)))


def oversized(target, pid, token):
    w, h = 5000, 10000
    s = connect(target)
    before = hwm_kb(pid)
    s.sendall(head(w, h, params_with(token), 1))
    chunk = b"\0" * (1 << 20)
    total = w * h * 4
    sent = 0
    answer = None
    s.setblocking(False)
    t_end = time.time() + 50
    while time.time() < t_end and answer is None:
        r, wr, _ = select.select([s], [s] if sent < total else [], [], 1.0)
        if r:
            s.setblocking(True)
            answer = read_answer(s, 10)
            break
        if wr:
            try:
                sent += s.send(chunk[:min(len(chunk), total - sent)])
            except (BlockingIOError, InterruptedError):
                pass
            except OSError:
                s.setblocking(True)
                answer = read_answer(s, 10)
                break
    growth = (hwm_kb(pid) - before) // 1024
    status = "%d:%s" % (answer[1], answer[2]) if isinstance(answer, tuple) else str(answer)
    print("status=%s sent_mb=%d rss_growth_mb=%d" % (status, sent >> 20, growth))


def headonly(target, w, h, token):
    s = connect(target)
    s.sendall(head(int(w), int(h), params_with(token), 1))
    a = read_answer(s, 5)
    if not isinstance(a, tuple):
        print("answer=%s" % a)
        return
    print("answer=%d:%s closed=%d" % (a[1], a[2], int(eof_within(s, 3))))


def busy(target, w, h):
    w, h = int(w), int(h)
    stop = threading.Event()
    big = frame(w, h, [("fov_y", "50")], 1)

    def feed():
        while not stop.is_set():
            try:
                s = connect(target)
                s.sendall(big + big)
                for _ in range(2):
                    if not isinstance(read_answer(s, 30), tuple):
                        break
                s.close()
            except OSError:
                time.sleep(0.05)

    feeders = [threading.Thread(target=feed, daemon=True) for _ in range(3)]
    for t in feeders:
        t.start()
    result = "none"
    t_end = time.time() + 40
    time.sleep(0.5)
    while time.time() < t_end:
        s = connect(target)
        s.sendall(head(w, h, [("fov_y", "50")], 77))
        a = read_answer(s, 0.5)
        s.close()
        if isinstance(a, tuple) and a[1] == 503:
            result = "%d:%s" % (a[1], a[2])
            break
        time.sleep(0.05)
    stop.set()
    print("probe=%s" % result)


def conns(target, n, srcs=None):
    srcs = srcs.split(",") if srcs else [None]
    time.sleep(0.5)  # the connections of a client before this one are closed
    socks = []
    for i in range(int(n)):
        try:
            socks.append(connect(target, src=srcs[i % len(srcs)]))
        except OSError:
            socks.append(None)
    time.sleep(0.5)
    # every socket waits in one window: the ones with nothing to read by
    # its end are open.  Refusals are sent as the connections are
    # accepted, so once one came the window ends when 1 s passes without
    # another (at most 3 s, all of it when none came); not one socket after
    # another (which made 256 open connections wait 0.05 s each)
    counts = {}
    t_end = time.time() + 3
    waiting = [s for s in socks if s is not None]
    readable = set()
    while waiting and time.time() < t_end:
        r, _, _ = select.select(waiting, [], [], max(0.0, min(1.0, t_end - time.time())))
        if not r and readable:
            break  # quiet for 1 s after an answer
        readable.update(r)
        waiting = [s for s in waiting if s not in readable]
    for s in socks:
        if s is None:
            k = "refused"
        elif s not in readable:
            k = "open"
        else:
            a = read_answer(s, 3)
            if isinstance(a, tuple):
                k = "%d:%s" % (a[1], a[2])
                if not eof_within(s, 1):
                    k += "(open)"
            elif a == "timeout":
                k = "open"
            else:
                k = a
        counts[k] = counts.get(k, 0) + 1
    print(" ".join("%s=%d" % kv for kv in sorted(counts.items())))


def one(target):
    s = connect(target)
    s.sendall(frame(8, 8, [("fov_y", "50")], 5))
    a = read_answer(s, 20)
    print("status=%s" % ("%d:%s" % (a[1], a[2]) if isinstance(a, tuple) else a))


if __name__ == "__main__":
    modes = {"stall": stall, "pipeline": pipeline, "oversized": oversized, "headonly": headonly,
             "busy": busy, "conns": conns, "one": one}
    modes[sys.argv[1]](*sys.argv[2:])
