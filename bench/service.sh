#!/usr/bin/env bash
# Speed figures of the job service, printed and never asserted (run by bench/run.sh):
#   - durable submissions per second and latency percentiles with 64 concurrent clients
#     (each 201 is answered only after its COMMIT with synchronous=FULL);
#   - claim throughput: claim + finish per second with 8 concurrent worker clients;
#   - log delay: from a line printed by the solver to the same line arriving at a client that
#     follows the job's log (poro logs -f). The solver here is a stand-in script that prints its
#     own clock every 0.1 s, so the delay is measured on one clock; the worker and server are real.
# Everything runs on 127.0.0.1 with a temporary state directory on the same disk as the tree.
#   bash bench/service.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/.."
root=$PWD
SUBMISSIONS=${SUBMISSIONS:-20000}
tmp=$(mktemp -d -p "$root/$build")
server=""
worker=""
trap '[ -n "$worker" ] && kill -TERM $worker 2>/dev/null; [ -n "$server" ] && kill -TERM $server 2>/dev/null; wait 2>/dev/null; rm -rf "$tmp"' EXIT

# one load-generator token stands for many users here: lift the per-token limit on requests in
# progress (docs/service.md §1, "Admission") above its 64 clients
"$build/poro-server" --listen 127.0.0.1:0 --state "$tmp/state" --user-max-queued 10000000 \
	--max-requests-per-token 1024 > "$tmp/server.log" 2>&1 &
server=$!
for i in $(seq 100); do [ -s "$tmp/state/server.url" ] && break; sleep 0.1; done
url=$(cat "$tmp/state/server.url")
user=$("$build/poro-server" token create --state "$tmp/state" --user bench --role user | tail -1)
pool=$("$build/poro-server" token create --state "$tmp/state" --user pool --role worker | tail -1)
python3 -c "import json; c = json.load(open('tests/cases/terzaghi.json')); c['time']['end'] = 0.01; json.dump(c, open('$tmp/case.json', 'w'))"

echo "durable submissions, 64 clients, $SUBMISSIONS jobs: $("$build/poro-load" submit --server "$url" --token "$user" \
	--case "$tmp/case.json" --clients 64 --count "$SUBMISSIONS" --key-prefix bench)"
echo "claims, 8 worker clients: $("$build/poro-load" claim --server "$url" --token "$pool" --clients 8 --count "$SUBMISSIONS")"

# the stand-in solver: answers 'version', prints "tick <epoch seconds>" every 0.1 s for 5 s
cat > "$tmp/ticker" <<'EOF'
#!/usr/bin/env bash
[ "${1:-}" = version ] && { echo "ticker"; exit 0; }
for i in $(seq 50); do echo "tick $(date +%s.%N)"; sleep 0.1; done
EOF
chmod +x "$tmp/ticker"
"$build/poro-worker" --server "$url" --token "$pool" --work "$tmp/work" --solver "$tmp/ticker" > "$tmp/worker.log" 2>&1 &
worker=$!
id=$(PORO_SERVER=$url PORO_TOKEN=$user "$build/poro" submit "$tmp/case.json")
PORO_SERVER=$url PORO_TOKEN=$user timeout 30 "$build/poro" logs -f "$id" 2>/dev/null | while IFS= read -r line; do
	case $line in tick*) echo "$(date +%s.%N) ${line#tick }" ;; esac
done > "$tmp/ticks.txt"
python3 - "$tmp/ticks.txt" <<'EOF'
import sys
pairs = [(float(a), float(b)) for a, b in (l.split() for l in open(sys.argv[1]) if len(l.split()) == 2)]
# lines printed before the follower was attached (it polls a queued job until it runs) measure the
# start-up, not the delay: the first second of the solver's output is reported apart
start = min(b for a, b in pairs) if pairs else 0
d = sorted(1e3 * (a - b) for a, b in pairs if b >= start + 1.0)
first = max([1e3 * (a - b) for a, b in pairs if b < start + 1.0] or [0])
if not d:
    print("log delay: no lines arrived")
else:
    pick = lambda q: d[min(len(d) - 1, max(0, int(round(q * len(d))) - 1))]
    print("log delay, solver line to following client, %d lines: p50 %.0f ms, p99 %.0f ms, max %.0f ms "
          "(lines of the first second, while the follower attached: up to %.0f ms)"
          % (len(d), pick(0.5), pick(0.99), d[-1], first))
EOF
