"""A hostile-request campaign against a running `cellmap serve`
(tests/serve_test.sh runs it): malformed and hostile URLs, raw malformed
HTTP, and 10^4 requests in a loop over kept-alive connections. Every
answer must be one of the statuses a bad request deserves (never a 5xx,
never a dropped connection but for raw garbage; a request of thousands of
query arguments libmicrohttpd leaves unanswered, but the others are
answered meanwhile), no answer may hold a
file outside Leaflet's (no "root:x:0:0"), and the server must answer
/info after each part.

  serve_campaign.py HOST PORT [REQUESTS]"""
import http.client, random, socket, sys

OK = {200, 400, 404, 405, 413, 414, 431}


def hostile_paths(rng):
    numbers = ["0", "-0", "1", "-1", "nan", "NaN", "-nan", "inf", "-inf", "infinity", "1e308",
               "-1e308", "1e400", "0x1p3", "1e-320", "", "%20", "1,5", "9" * 40, "-" + "9" * 40,
               "%00", "1%00", "1e", "e1", "..", "%2e%2e", "1/2", "%D9%A3"]
    ints = ["0", "-1", "1", "-3", "-4", "4", "9223372036854775807", "-9223372036854775808",
            "99999999999999999999", "4398046511104", "-4398046511104", "17179869184", "x", "",
            "00000000000000000000001", "+1", "1.0", "%31"]
    fixed = ["/", "/info", "/cell", "/tiles", "/tiles/", "/tiles/0", "/tiles/0/0", "/tiles/0/0/0",
             "/tiles/0/0/0.png/", "/tiles/0/0/0.png?x=1", "/tiles//0/0.png", "/..", "/../../etc/passwd",
             "/leaflet/", "/leaflet/../../../../etc/passwd", "/leaflet/%2e%2e/%2e%2e/etc/passwd",
             "/leaflet/images/../../../../etc/passwd", "/leaflet/leaflet.js%00.png",
             "/leaflet//etc/passwd", "//etc/passwd", "/%2F%2Fetc%2Fpasswd", "/index.html",
             "/info?" + "a=1&" * 1000, "/cell?x=1&x=2&y=3", "/cell?y=1", "/" + "a" * 5000]
    paths = list(fixed)
    zooms = ["0", "-1", "1", "-4", "x", "", "+0", "9223372036854775807", "-2147483649"]
    for _ in range(300):
        paths.append("/tiles/%s/%s/%s.png" % (rng.choice(zooms), rng.choice(ints), rng.choice(ints)))
        paths.append("/cell?x=%s&y=%s&steps=%s" % (rng.choice(numbers), rng.choice(numbers),
                                                   rng.choice(ints)))
    return paths


def request(conn, method, path, body=None):
    conn.request(method, path, body=body)
    r = conn.getresponse()
    return r.status, r.read()


def alive(host, port):
    c = http.client.HTTPConnection(host, port, timeout=60)
    status, _ = request(c, "GET", "/info")
    c.close()
    return status == 200


def raw(host, port, data):
    """Sends raw bytes; returns what came back (b"" if closed)."""
    s = socket.create_connection((host, port), timeout=5)  # a body announced, not sent: no answer
    try:
        s.sendall(data)
        s.shutdown(socket.SHUT_WR)
        got = b""
        while True:
            chunk = s.recv(65536)
            if not chunk:
                return got
            got += chunk
    except OSError:
        return b""
    finally:
        s.close()


def main():
    host, port = sys.argv[1], int(sys.argv[2])
    total = int(sys.argv[3]) if len(sys.argv) > 3 else 10000
    rng = random.Random(49)
    bad = []
    paths = hostile_paths(rng)
    conn = http.client.HTTPConnection(host, port, timeout=60)
    sent = 0
    while sent < total:
        path = paths[sent % len(paths)] if sent < len(paths) else rng.choice(paths)
        method = rng.choice(["GET", "GET", "GET", "HEAD", "POST", "PUT", "DELETE", "OPTIONS"])
        try:
            status, body = request(conn, method, path, body=b"x" * rng.choice([0, 10, 5000])
                                   if method in ("POST", "PUT") else None)
        except (http.client.HTTPException, OSError) as e:
            bad.append("%s %s: %s" % (method, path[:80], e))
            conn.close()
            conn = http.client.HTTPConnection(host, port, timeout=60)
            sent += 1
            continue
        if status not in OK:
            bad.append("%s %s: status %d %r" % (method, path[:80], status, body[:200]))
        if b"root:x:0:0" in body:
            bad.append("%s %s served /etc/passwd" % (method, path[:80]))
        if status == 200 and method in ("POST", "PUT", "DELETE", "OPTIONS"):
            bad.append("%s %s answered 200" % (method, path[:80]))
        sent += 1
    conn.close()
    if not alive(host, port):
        bad.append("the server stopped answering after %d requests" % total)
    garbage = [b"\x00\x01\x02\r\n\r\n", b"GET\r\n\r\n", b"GET / HTTP/9.9\r\n\r\n",
               b"GET /info HTTP/1.1\r\nHost: x\r\n" + b"X-A: " + b"a" * 100000 + b"\r\n\r\n",
               b"GET /" + b"a" * 100000 + b" HTTP/1.1\r\n\r\n",
               b"POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 1000000000\r\n\r\nxx",
               b"GET /info HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n",
               b"GET /tiles/0/0/-1.png HTTP/1.0\r\n\r\n" * 20]
    for g in garbage:
        got = raw(host, port, g)
        if b"root:x:0:0" in got or b" 500 " in got[:20]:
            bad.append("raw %r: %r" % (g[:40], got[:100]))
    if not alive(host, port):
        bad.append("the server stopped answering after raw malformed requests")
    # thousands of query arguments exhaust libmicrohttpd's pool for the
    # connection, which it then leaves unanswered until its idle timeout:
    # the others must be answered meanwhile
    stuck = http.client.HTTPConnection(host, port, timeout=3)
    try:
        status, _ = request(stuck, "GET", "/info?" + "a=1&" * 5000)
        if status not in OK:
            bad.append("5000 query arguments: status %d" % status)
    except OSError:
        pass
    if not alive(host, port):
        bad.append("the server stopped answering while a connection of 5000 query arguments waits")
    stuck.close()
    print("%d requests and %d raw malformed ones: %d problems" % (total, len(garbage), len(bad)))
    if bad:
        sys.exit("\n".join(bad[:20]))


if __name__ == "__main__":
    main()
