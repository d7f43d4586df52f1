#!/usr/bin/env python3
r"""Raw-socket HTTP clients for tests/e2e/hostile_http.sh: slow, malformed
and persistent clients that curl cannot play.  Loopback only; every wait
is bounded.  Each command prints one line the script checks.

  raw PORT REQUEST WAIT         send the request (\r, \n, \xNN escapes), print 'STATUS SECONDS' of the
                                answer (or 'none SECONDS' when the
                                connection closed or WAIT passed without one)
  trickle PORT GAP SECONDS      POST /v1/ao with Content-Length 100000, one
                                byte every GAP s; print 'STATUS SECONDS' of
                                the answer or 'closed SECONDS' / 'open SECONDS'
  connect PORT WAIT             connect and send GET /healthz: 'refused',
                                'STATUS SECONDS' or 'none SECONDS'
  keepalive PORT N              N GET /healthz on one connection: 'answered K
                                close-header C' (C: answers with Connection: close)
  slow PORT N ADDRS             N slow connections from ADDRS source
                                addresses 127.0.9.x (half stalled in the
                                headers, half in a POST body), then GET
                                /healthz from 127.0.0.1: 'held H healthz
                                STATUS MS'
  perclient PORT N              N connections from 127.0.8.1, each sending
                                a partial request, then one more from there
                                and one from 127.0.8.2: 'held H same
                                RESULT other RESULT'
"""
import resource
import socket
import sys
import time


def status_of(data):
    if data.startswith(b"HTTP/1."):
        parts = data.split(b" ", 2)
        if len(parts) > 1:
            return parts[1].decode("ascii", "replace")
    return None


def read_answer(s, wait):
    """Reads until a status line and its headers arrived, the peer closed,
    or `wait` seconds passed.  Returns (status or None, bytes)."""
    t0 = time.monotonic()
    data = b""
    while time.monotonic() - t0 < wait:
        s.settimeout(max(0.05, wait - (time.monotonic() - t0)))
        try:
            chunk = s.recv(65536)
        except socket.timeout:
            break
        except OSError:
            break
        if not chunk:
            break
        data += chunk
        if b"\r\n\r\n" in data:
            break
    return status_of(data), data


def cmd_raw(port, text, wait):
    t0 = time.monotonic()
    s = socket.create_connection(("127.0.0.1", port), timeout=5)
    s.sendall(text.encode('latin-1').decode('unicode_escape').encode('latin-1'))
    st, _ = read_answer(s, wait)
    print("%s %.2f" % (st or "none", time.monotonic() - t0))


def cmd_trickle(port, gap, seconds):
    t0 = time.monotonic()
    s = socket.create_connection(("127.0.0.1", port), timeout=5)
    s.sendall(b"POST /v1/ao HTTP/1.1\r\nHost: x\r\nContent-Type: image/x-exr\r\n"
              b"Content-Length: 100000\r\n\r\n")
    s.setblocking(False)
    data = b""
    while time.monotonic() - t0 < seconds:
        try:
            chunk = s.recv(65536)
            if not chunk:
                st = status_of(data)
                print("%s %.2f" % (st or "closed", time.monotonic() - t0))
                return
            data += chunk
            if b"\r\n\r\n" in data:
                print("%s %.2f" % (status_of(data), time.monotonic() - t0))
                return
        except BlockingIOError:
            pass
        except OSError:
            print("closed %.2f" % (time.monotonic() - t0))
            return
        try:
            s.send(b"x")
        except OSError:
            st = status_of(data)
            print("%s %.2f" % (st or "closed", time.monotonic() - t0))
            return
        time.sleep(gap)
    print("open %.2f" % (time.monotonic() - t0))


def cmd_connect(port, wait):
    t0 = time.monotonic()
    try:
        s = socket.create_connection(("127.0.0.1", port), timeout=wait)
    except ConnectionRefusedError:
        print("refused %.2f" % (time.monotonic() - t0))
        return
    except OSError:
        print("none %.2f" % (time.monotonic() - t0))
        return
    try:
        s.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n")
    except OSError:
        print("refused %.2f" % (time.monotonic() - t0))
        return
    st, _ = read_answer(s, wait)
    print("%s %.2f" % (st or "none", time.monotonic() - t0))


def cmd_keepalive(port, n):
    s = socket.create_connection(("127.0.0.1", port), timeout=5)
    answered = closes = 0
    for _ in range(n):
        try:
            s.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n")
        except OSError:
            break
        st, data = read_answer(s, 5)
        if st != "200":
            break
        answered += 1
        head = data.split(b"\r\n\r\n", 1)[0].lower()
        if b"connection: close" in head:
            closes += 1
        # the body: "ok\n" (Content-Length 3)
        rest = data.split(b"\r\n\r\n", 1)[1] if b"\r\n\r\n" in data else b""
        while len(rest) < 3:
            try:
                c = s.recv(16)
            except OSError:
                break
            if not c:
                break
            rest += c
    print("answered %d close-header %d" % (answered, closes))


def open_many(port, n, addrs, partial):
    socks = []
    for i in range(n):
        src = "127.0.9.%d" % (1 + i % addrs) if addrs else None
        s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        if src:
            s.bind((src, 0))
        s.setblocking(False)
        try:
            s.connect(("127.0.0.1", port))
        except BlockingIOError:
            pass
        except OSError:
            s.close()
            continue
        socks.append((s, partial(i)))
    time.sleep(0.5)
    held = 0
    for s, data in socks:
        try:
            s.send(data)
            held += 1
        except OSError:
            pass
    return socks, held


def cmd_slow(port, n, addrs):
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft < n + 64:
        resource.setrlimit(resource.RLIMIT_NOFILE, (min(hard, n + 64), hard))

    def partial(i):
        if i % 2:
            return b"GET /healthz HTTP/1.1\r\nHost: x\r\nX-Slow: "
        return (b"POST /v1/ao HTTP/1.1\r\nHost: x\r\nContent-Type: image/x-exr\r\n"
                b"Content-Length: 100000\r\n\r\nxx")

    socks, held = open_many(port, n, addrs, partial)
    time.sleep(1.0)
    t0 = time.monotonic()
    st = None
    try:
        s = socket.create_connection(("127.0.0.1", port), timeout=10)
        s.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n")
        st, _ = read_answer(s, 10)
    except OSError:
        pass
    ms = (time.monotonic() - t0) * 1000
    # still held: the ones the daemon did not close
    alive = 0
    for s, _ in socks:
        try:
            s.setblocking(False)
            if s.recv(1, socket.MSG_PEEK) == b"":
                continue
        except BlockingIOError:
            alive += 1
            continue
        except OSError:
            continue
    print("held %d open %d healthz %s %.0f" % (held, alive, st or "none", ms))


def cmd_perclient(port, n):
    socks = []
    for _ in range(n):
        s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        s.bind(("127.0.8.1", 0))
        s.settimeout(5)
        s.connect(("127.0.0.1", port))
        s.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n")
        socks.append(s)
    time.sleep(0.5)

    def probe(src):
        t0 = time.monotonic()
        s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        s.bind((src, 0))
        s.settimeout(3)
        try:
            s.connect(("127.0.0.1", port))
            s.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n")
        except OSError:
            return "refused"
        st, _ = read_answer(s, 3)
        return "%s/%.1f" % (st or "none", time.monotonic() - t0)

    print("held %d same %s other %s" % (len(socks), probe("127.0.8.1"), probe("127.0.8.2")))


def main(argv):
    cmd, port = argv[1], int(argv[2])
    if cmd == "raw":
        cmd_raw(port, argv[3], float(argv[4]))
    elif cmd == "trickle":
        cmd_trickle(port, float(argv[3]), float(argv[4]))
    elif cmd == "connect":
        cmd_connect(port, float(argv[3]))
    elif cmd == "keepalive":
        cmd_keepalive(port, int(argv[3]))
    elif cmd == "slow":
        cmd_slow(port, int(argv[3]), int(argv[4]))
    elif cmd == "perclient":
        cmd_perclient(port, int(argv[3]))
    else:
        sys.exit("unknown command " + cmd)


if __name__ == "__main__":
    main(sys.argv)
