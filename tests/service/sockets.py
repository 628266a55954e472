#!/usr/bin/env python3
"""sockets.py - hostile and careless clients for the service tests, on real sockets.

    sockets.py idle  PORT --from ADDR --count N --hold SECONDS [--ready FILE]
        N connections from ADDR that send nothing
    sockets.py slow  PORT --from ADDR --count N --hold SECONDS [--interval S] [--ready FILE]
        N connections that send a request head one byte every S seconds (slowloris)
    sockets.py keepalive PORT --from ADDR --count N --hold SECONDS [--ready FILE]
        N connections that send one complete GET /healthz, read the answer, then idle
    sockets.py slowbody PORT --from ADDR --token T --hold SECONDS
        one POST /v1/jobs with Content-Length 100000 whose body comes one byte a second

Each connection is watched until the server closes it or SECONDS pass. Prints one JSON object:
{"opened", "failed_to_open", "closed_by_server", "still_open", "close_seconds": [...],
 "answers": {"STATUS CODE": count}, "non_json_answers": count}, where an answer is what the server
wrote before closing (its status line and the error code of its JSON body). ADDR may be any
127.0.0.0/8 address, or several separated by commas (taken in turn): Linux routes them all to the
loopback interface, so several client addresses can be tried on one machine without privileges.
"""
import argparse
import json
import resource
import selectors
import socket
import sys
import time


def raise_fd_limit(wanted):
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    target = min(hard, max(soft, wanted))
    if target > soft:
        resource.setrlimit(resource.RLIMIT_NOFILE, (target, hard))
    return target


def parse_answer(data):
    """(status, code) of an HTTP answer, code None when the body is not the API's JSON error."""
    head, _, body = data.partition(b"\r\n\r\n")
    try:
        status = int(head.split(b" ")[1])
    except (IndexError, ValueError):
        return None, None
    try:
        code = json.loads(body.decode())["error"]["code"]
    except (ValueError, KeyError, TypeError, UnicodeDecodeError):
        code = None if status >= 400 else "ok"
    return status, code


def main():
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=["idle", "slow", "keepalive", "slowbody"])
    p.add_argument("port", type=int)
    p.add_argument("--from", dest="source", default="127.0.0.1")
    p.add_argument("--count", type=int, default=1)
    p.add_argument("--hold", type=float, default=10)
    p.add_argument("--interval", type=float, default=0.5)
    p.add_argument("--token", default="")
    p.add_argument("--ready", default="")
    a = p.parse_args()
    raise_fd_limit(a.count + 64)

    head = b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nUser-Agent: slow-client\r\nX-Pad: " + b"p" * 200 + b"\r\n\r\n"
    if a.mode == "slowbody":
        head = (b"POST /v1/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + a.token.encode() +
                b"\r\nContent-Type: application/json\r\nContent-Length: 100000\r\n\r\n")
    sel = selectors.DefaultSelector()
    conns = {}
    failed = 0
    start = time.monotonic()
    for i in range(a.count):
        s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        sources = a.source.split(",")
        try:
            s.bind((sources[i % len(sources)], 0))
            s.settimeout(5)
            s.connect(("127.0.0.1", a.port))
            s.setblocking(False)
        except OSError:
            failed += 1
            s.close()
            continue
        c = {"sock": s, "sent": 0, "data": b"", "opened": time.monotonic(), "closed": None}
        if a.mode in ("keepalive", "slowbody"):
            s.setblocking(True)
            try:
                s.sendall(head)
                if a.mode == "keepalive":  # read the whole answer, then idle on the open connection
                    s.settimeout(5)
                    answer = b""
                    while b"\r\n\r\n" not in answer or len(answer.partition(b"\r\n\r\n")[2]) < 10:
                        more = s.recv(4096)
                        if not more:
                            break
                        answer += more
            except OSError:
                pass  # the server refused or dropped it: the watch below sees it closed
            s.setblocking(False)
            c["sent"] = len(head)
        conns[s.fileno()] = c
        sel.register(s, selectors.EVENT_READ, c)
    if a.ready:
        open(a.ready, "w").write("%d\n" % len(conns))

    next_byte = time.monotonic()
    while time.monotonic() - start < a.hold and any(c["closed"] is None for c in conns.values()):
        for key, _ in sel.select(timeout=0.05):
            c = key.data
            try:
                more = c["sock"].recv(65536)
            except (BlockingIOError, InterruptedError):
                continue
            except OSError:
                more = b""
            if more and a.mode != "keepalive":
                c["data"] += more
            elif more:
                continue
            if not more:
                c["closed"] = time.monotonic()
                sel.unregister(c["sock"])
        now = time.monotonic()
        if a.mode in ("slow", "slowbody") and now >= next_byte:
            next_byte = now + a.interval
            for c in conns.values():
                if c["closed"] is None:
                    data = head if a.mode == "slow" else b"{"
                    i = c["sent"] % len(data) if a.mode == "slow" else 0
                    try:
                        c["sock"].send(data[i:i + 1])
                        c["sent"] += 1
                    except OSError:
                        pass
    answers = {}
    non_json = 0
    close_seconds = []
    for c in conns.values():
        if c["closed"] is not None:
            close_seconds.append(round(c["closed"] - c["opened"], 3))
        if c["data"]:
            status, code = parse_answer(c["data"])
            key = "%s %s" % (status, code)
            answers[key] = answers.get(key, 0) + 1
            non_json += code is None
        c["sock"].close()
    print(json.dumps({"opened": len(conns), "failed_to_open": failed,
                      "closed_by_server": len(close_seconds),
                      "still_open": len(conns) - len(close_seconds),
                      "close_seconds": sorted(close_seconds), "answers": answers,
                      "non_json_answers": non_json}))


if __name__ == "__main__":
    sys.exit(main())
