#!/usr/bin/env python3
"""Bounded load test for a running `nurbsx serve` on the loopback interface.

Sends a fixed number of requests from a fixed number of client threads (each with its own
keep-alive connection), then prints throughput, the latency percentiles and the replies by
status. It stops by itself: after --requests requests or --max-seconds, whichever is first.
Only loopback addresses are accepted (127.0.0.0/8, localhost, ::1).

    nurbsx serve --addr 127.0.0.1:8080 &
    python3 scripts/load/load.py evaluate --requests 5000 --concurrency 8
    python3 scripts/load/load.py convert --file part.igs --to step --requests 500
    python3 scripts/load/load.py evaluate --sweep 2,8,16,32 --requests 2000

With --sweep, the same bounded run is repeated for each client count and one table row is
printed per count: throughput, p50 and p99 latency, and the share of 503 replies.

Python 3.8+ standard library only.
"""

import argparse
import http.client
import ipaddress
import json
import math
import socket
import sys
import threading
import time
import urllib.parse

W = math.sqrt(0.5)
CIRCLE = {
    "degree": 2,
    "knots": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
    "control_points": [[1, 0, 0], [1, 1, 0], [0, 1, 0], [-1, 1, 0], [-1, 0, 0],
                       [-1, -1, 0], [0, -1, 0], [1, -1, 0], [1, 0, 0]],
    "weights": [1, W, 1, W, 1, W, 1, W, 1],
}
MAX_REQUESTS = 1_000_000


def loopback_only(host):
    """Refuses anything but a loopback address."""
    try:
        infos = socket.getaddrinfo(host, None)
    except socket.gaierror as e:
        sys.exit(f"cannot resolve {host!r}: {e}")
    for info in infos:
        if not ipaddress.ip_address(info[4][0]).is_loopback:
            sys.exit(f"{host!r} is not a loopback address; this script only targets 127.0.0.1/::1")


def percentile(sorted_values, p):
    """Nearest-rank percentile of an already sorted list."""
    if not sorted_values:
        return float("nan")
    rank = max(1, math.ceil(p / 100.0 * len(sorted_values)))
    return sorted_values[rank - 1]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("endpoint", choices=["evaluate", "convert"])
    ap.add_argument("--url", default="http://127.0.0.1:8080", help="server base URL (loopback only)")
    ap.add_argument("--requests", type=int, default=2000, help="total requests (bounded)")
    ap.add_argument("--concurrency", type=int, default=8, help="client threads")
    ap.add_argument("--sweep", help="comma-separated client counts, e.g. 2,8,16,32: one table row each")
    ap.add_argument("--max-seconds", type=float, default=120.0, help="stop after this long")
    ap.add_argument("--points", type=int, default=100, help="evaluate: parameters per request")
    ap.add_argument("--file", help="convert: the sample file to send")
    ap.add_argument("--to", default="step", choices=["step", "iges"], help="convert: output format")
    args = ap.parse_args()

    if not 1 <= args.requests <= MAX_REQUESTS:
        sys.exit(f"--requests must be in 1..{MAX_REQUESTS}")
    counts = [args.concurrency]
    if args.sweep:
        try:
            counts = [int(c) for c in args.sweep.split(",")]
        except ValueError:
            sys.exit("--sweep takes comma-separated integers")
    if not all(1 <= c <= 256 for c in counts):
        sys.exit("client counts must be in 1..256")
    url = urllib.parse.urlsplit(args.url)
    if url.scheme != "http" or not url.hostname:
        sys.exit("--url must be http://HOST:PORT")
    loopback_only(url.hostname)
    port = url.port or 80

    if args.endpoint == "evaluate":
        n = max(1, args.points)
        body = json.dumps({"geometry": CIRCLE, "params": [[i / n] for i in range(n + 1)]}).encode()
        path, headers = "/v1/evaluate", {"Content-Type": "application/json"}
    else:
        if not args.file:
            sys.exit("convert needs --file SAMPLE")
        with open(args.file, "rb") as f:
            body = f.read()
        path = f"/v1/convert?to={args.to}"
        headers = {"Content-Type": "application/octet-stream"}
    headers["Content-Length"] = str(len(body))

    if args.sweep:
        print(f"endpoint {path}  ({len(body)} bytes per request, {args.requests} requests per row)")
        print("| clients | req/s | p50 ms | p99 ms | 503 share | other non-2xx | transport errors |")
        print("| --- | --- | --- | --- | --- | --- | --- |")
    failed = False
    for clients in counts:
        done, errors, elapsed, statuses, latencies = run(
            url.hostname, port, path, body, headers, args.requests, clients, args.max_seconds)
        ok = sum(v for k, v in statuses.items() if 200 <= k < 300)
        shed = statuses.get(503, 0)
        failed |= ok != done or bool(errors)
        ms = lambda s: f"{s * 1000:.2f} ms"
        if args.sweep:
            print(f"| {clients} | {done / elapsed:.1f} | {percentile(latencies, 50) * 1000:.2f} "
                  f"| {percentile(latencies, 99) * 1000:.2f} | {100.0 * shed / max(done, 1):.2f} % "
                  f"| {done - ok - shed} | {len(errors)} |")
            continue
        print(f"endpoint      {path}  ({len(body)} bytes per request)")
        print(f"requests      {done} answered, {len(errors)} transport errors, in {elapsed:.2f} s "
              f"with {clients} clients")
        print(f"statuses      {dict(sorted(statuses.items()))}")
        print(f"throughput    {done / elapsed:.1f} req/s ({ok / elapsed:.1f} req/s 2xx)")
        if done:
            print(f"latency       p50 {ms(percentile(latencies, 50))}  p90 {ms(percentile(latencies, 90))}  "
                  f"p99 {ms(percentile(latencies, 99))}  max {ms(latencies[-1])}")
        if errors:
            print(f"first errors  {errors[:3]}")
    return 1 if failed else 0


def run(host, port, path, body, headers, requests, concurrency, max_seconds):
    """One bounded run: (answered, transport errors, seconds, statuses, sorted latencies)."""
    lock = threading.Lock()
    state = {"next": 0}
    latencies, statuses, errors = [], {}, []
    deadline = time.monotonic() + max_seconds

    def take():
        with lock:
            if state["next"] >= requests or time.monotonic() > deadline:
                return False
            state["next"] += 1
            return True

    def worker():
        conn = http.client.HTTPConnection(host, port, timeout=30)
        mine, codes = [], {}
        while take():
            t0 = time.perf_counter()
            try:
                conn.request("POST", path, body=body, headers=headers)
                reply = conn.getresponse()
                reply.read()
                status = reply.status
                if reply.getheader("Connection", "").lower() == "close":
                    conn.close()
            except (OSError, http.client.HTTPException) as e:
                conn.close()
                with lock:
                    errors.append(repr(e))
                continue
            mine.append(time.perf_counter() - t0)
            codes[status] = codes.get(status, 0) + 1
        conn.close()
        with lock:
            latencies.extend(mine)
            for k, v in codes.items():
                statuses[k] = statuses.get(k, 0) + v

    threads = [threading.Thread(target=worker, daemon=True) for _ in range(concurrency)]
    start = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    elapsed = time.perf_counter() - start
    latencies.sort()
    return len(latencies), errors, elapsed, statuses, latencies


if __name__ == "__main__":
    sys.exit(main())
