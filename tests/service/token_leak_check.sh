#!/usr/bin/env bash
# token_leak_check.sh - no bearer token in any log the tests produce. Run by tests/run.sh after the
# service tests: every token they created is listed in SVC_TOKENS_LOG (svc_token and
# svc_record_token in tests/service/lib.sh), and the logs they left (servers' stdout and stderr,
# workers' logs) were kept in SVC_KEEP_LOGS. This greps those logs, the access log SVC_ROUTES_LOG
# and BUILD_DIR/test-output.txt (what every test printed) for every recorded token and for
# anything shaped like a token (poro_ and 43 URL-safe base64 characters), and fails naming the
# file and line, never the token. The only places a token may appear are the answer of
# POST /v1/tokens and the stdout of `poro-server token create`, which the tests capture rather
# than log.
#   bash tests/service/token_leak_check.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
tokens=${SVC_TOKENS_LOG:-$build/service-tokens.txt}
kept=${SVC_KEEP_LOGS:-$build/service-logs}
routes=${SVC_ROUTES_LOG:-$build/service-routes.log}
python3 - "$tokens" "$kept" "$routes" "$build/test-output.txt" <<'PY'
import os, re, sys
tokens_file, kept, routes, output = sys.argv[1:5]
URLSAFE = "A-Za-z0-9_-"
shape = re.compile(r"(?<![%s])poro_[%s]{43}(?![%s])" % (URLSAFE, URLSAFE, URLSAFE))

def check(name, ok, why):
    print("PASS " + name if ok else "FAIL %s: %s" % (name, why))

recorded = []
if os.path.exists(tokens_file):
    recorded = sorted(set(l.strip() for l in open(tokens_file, errors="replace") if l.strip()))
check("tokens_recorded", len(recorded) > 0, "no token recorded in %s (run the service tests first)" % tokens_file)
files = []
if os.path.isdir(kept):
    files = sorted(os.path.join(kept, f) for f in os.listdir(kept) if os.path.isfile(os.path.join(kept, f)))
check("service_logs_kept", len(files) > 0, "no logs kept in %s (run the service tests first)" % kept)
files += [f for f in (routes, output) if os.path.isfile(f)]

# one alternation of every recorded token: one pass per line whatever their number
known = re.compile("|".join(re.escape(t) for t in recorded)) if recorded else None
hits_known, hits_shape, lines = [], [], 0
for path in files:
    with open(path, "rb") as f:
        for number, raw in enumerate(f, 1):
            lines += 1
            line = raw.decode("utf-8", "replace")
            if known and known.search(line):
                hits_known.append("%s:%d" % (path, number))
            elif shape.search(line):
                hits_shape.append("%s:%d" % (path, number))
print("INFO token-leak check: %d files, %d lines, %d recorded tokens" % (len(files), lines, len(recorded)))
check("no_recorded_token_in_logs", not hits_known,
      "%d lines hold a token the tests created, first: %s" % (len(hits_known), ", ".join(hits_known[:10])))
check("no_token_shaped_text_in_logs", not hits_shape,
      "%d lines hold text shaped like a token, first: %s" % (len(hits_shape), ", ".join(hits_shape[:10])))
PY
