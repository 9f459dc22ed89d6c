#!/usr/bin/env python3
"""Peak memory of `nurbsx serve` under the largest in-limit request of each endpoint.

For each case a fresh server is started on 127.0.0.1 (default limits unless --serve-args
says otherwise), one request is sent, and the server's peak resident memory (VmHWM of
/proc/PID/status, Linux) is read before the server is stopped with SIGTERM. Prints one
Markdown table row per case: request size, status, reply size, time and peak RSS.

    cargo build --release
    python3 scripts/load/worst.py ./target/release/nurbsx

The cases sit just under the default limits (64 MiB body, 64 MiB reply estimate); one
case sends a 64 MiB evaluation body that the reply limit refuses. Python 3.8+ standard
library only; bounded: one request per case, each with a 300 s timeout.
"""

import argparse
import http.client
import json
import math
import os
import signal
import socket
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from load import CIRCLE  # noqa: E402  (the same circle as the load test)

PATCH = {
    "degree_u": 2, "degree_v": 2,
    "knots_u": [0, 0, 0, 1, 1, 1], "knots_v": [0, 0, 0, 1, 1, 1],
    "control_points": [[[0, 0, 0], [0, 1, 0.3], [0, 2, 0]], [[1, 0, 0.2], [1, 1, 1.1], [1, 2, 0.1]],
                       [[2, 0, 0], [2, 1, -0.4], [2, 2, 0.5]]],
}


def grid_surface(n):
    """A bicubic surface with an n x n control net, clamped uniform knots."""
    knots = [0.0] * 4 + [i / (n - 3) for i in range(1, n - 3)] + [1.0] * 4
    net = [[[i / n, j / n, math.sin(i * 0.37) * math.cos(j * 0.23)] for j in range(n)]
           for i in range(n)]
    return {"degree_u": 3, "degree_v": 3, "knots_u": knots, "knots_v": knots,
            "control_points": net}


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def peak_rss_mib(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def run_case(binary, extra, method_path, body, content_type):
    port = free_port()
    server = subprocess.Popen([binary, "serve", "--addr", f"127.0.0.1:{port}"] + extra,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        for _ in range(200):
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                time.sleep(0.05)
        idle = peak_rss_mib(server.pid)
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=300)
        t0 = time.perf_counter()
        conn.request("POST", method_path, body=body, headers={"Content-Type": content_type})
        reply = conn.getresponse()
        data = reply.read()
        took = time.perf_counter() - t0
        peak = peak_rss_mib(server.pid)
        return reply.status, data, took, idle, peak
    finally:
        server.send_signal(signal.SIGTERM)
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            server.kill()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("binary", help="path to the nurbsx binary")
    ap.add_argument("--serve-args", default="", help="extra `serve` options, space-separated")
    args = ap.parse_args()
    extra = args.serve_args.split()
    if not os.path.exists("/proc/self/status"):
        sys.exit("needs Linux /proc")

    surface = grid_surface(700)
    step = None
    cases = []
    # Evaluate: the most curve points whose reply estimate (124 bytes each) fits 64 MiB.
    n = 540_000
    cases.append(("evaluate, 540k curve points", "/v1/evaluate", "application/json",
                  json.dumps({"geometry": CIRCLE, "params": [[i / n] for i in range(n)]})))
    # Evaluate: the most surface points with derivatives, normals and curvature.
    n = 59_000
    cases.append(("evaluate, 59k surface points, 2nd derivatives, normals, curvature",
                  "/v1/evaluate", "application/json",
                  json.dumps({"geometry": PATCH, "derivatives": 2, "normals": True, "curvature": True,
                              "params": [[(i % 243) / 242, (i // 243) / 242] for i in range(n)]})))
    # Evaluate: 2 M curve points with the reply limit raised to 1 GiB: a 140 MiB reply,
    # streamed (the server holds a few chunks of it at a time).
    n = 2_000_000
    cases.append(("evaluate, 2 M curve points, streamed (`--max-reply-bytes 1GiB`)",
                  "/v1/evaluate", "application/json",
                  json.dumps({"geometry": CIRCLE, "params": [[i / n] for i in range(n)]}),
                  ["--max-reply-bytes", "1GiB"]))
    # Evaluate: a 64 MiB body of 10 M points, refused by the reply estimate.
    text = '{"geometry":' + json.dumps(CIRCLE) + ',"params":['
    text += ",".join(["[0.5]"] * 10_000_000) + "]}"
    cases.append(("evaluate, 64 MiB body of 10 M points (refused)", "/v1/evaluate",
                  "application/json", text))
    # Tessellate: a curve near the reply cap (about 737k points of 91 bytes).
    cases.append(("tessellate, circle at tolerance 1.3e-11 (about 620k points)", "/v1/tessellate",
                  "application/json", json.dumps({"geometry": CIRCLE, "tolerance": 1.3e-11})))
    # Tessellate: the quadric patch as binary glTF, at the finest tolerance whose mesh fits
    # the working-memory budget (950k vertices of the 1.26 M it allows; the next finer
    # mesh the mesher makes has more) and at one whose mesh does not (refused during the
    # work, the estimate being a lower bound); then the circle as SVG (the reply just
    # under 64 MiB).
    cases.append(("tessellate, 3 x 3 patch at tolerance 2e-6, glTF", "/v1/tessellate",
                  "application/json",
                  json.dumps({"geometry": PATCH, "tolerance": 2e-6, "format": "glb"})))
    cases.append(("tessellate, 3 x 3 patch at tolerance 1.4e-6, glTF (refused)", "/v1/tessellate",
                  "application/json",
                  json.dumps({"geometry": PATCH, "tolerance": 1.4e-6, "format": "glb"})))
    cases.append(("tessellate, circle at tolerance 2.5e-11, SVG", "/v1/tessellate",
                  "application/json",
                  json.dumps({"geometry": CIRCLE, "tolerance": 2.5e-11, "format": "svg"})))
    # The patch as SVG: the finest of these tolerances whose picture fits the reply limit.
    cases.append(("tessellate, 3 x 3 patch at tolerance 1e-5, SVG", "/v1/tessellate",
                  "application/json",
                  json.dumps({"geometry": PATCH, "tolerance": 1e-5, "format": "svg"})))
    # Degree elevation by 1 in u: of a 480 x 480 bicubic surface (in limit: about 460k poles
    # out) and of the 700 x 700 one (the written-file estimate, 950k poles, is refused).
    cases.append(("degree-elevate, 480 x 480 bicubic surface, by 1 in u", "/v1/degree-elevate",
                  "application/json",
                  json.dumps({"geometry": grid_surface(480), "by": 1, "direction": "u"})))
    cases.append(("degree-elevate, 700 x 700 bicubic surface, by 1 in u (refused)",
                  "/v1/degree-elevate", "application/json",
                  json.dumps({"geometry": surface, "by": 1, "direction": "u"})))
    # Convert: the same surface, model JSON to STEP; then the STEP to IGES, info, validate.
    cases.append(("convert, 700 x 700 surface, JSON to STEP", "/v1/convert?to=step",
                  "application/json", json.dumps(surface)))
    print("| case | request | status | reply | time | idle RSS | peak RSS |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for name, path, ctype, body, *case_extra in cases:
        body = body.encode()
        case_args = extra + (case_extra[0] if case_extra else [])
        status, data, took, idle, peak = run_case(args.binary, case_args, path, body, ctype)
        if path.startswith("/v1/convert") and status == 200:
            step = data
        print(f"| {name} | {len(body) / 2**20:.1f} MiB | {status} | {len(data) / 2**20:.1f} MiB "
              f"| {took:.1f} s | {idle:.0f} MiB | {peak:.0f} MiB |", flush=True)
    if step is not None:
        for name, path in [("convert, that STEP to IGES", "/v1/convert?to=iges"),
                           ("info, that STEP", "/v1/info"), ("validate, that STEP", "/v1/validate")]:
            status, data, took, idle, peak = run_case(args.binary, extra, path, step, "model/step")
            print(f"| {name} | {len(step) / 2**20:.1f} MiB | {status} | {len(data) / 2**20:.1f} MiB "
                  f"| {took:.1f} s | {idle:.0f} MiB | {peak:.0f} MiB |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
