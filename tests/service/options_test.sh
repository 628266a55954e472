#!/usr/bin/env bash
# options_test.sh - poro-server's and poro-worker's command lines, read by getopt_long (GNU habits):
# --help prints every option on stdout and exits 0 (the server's lists every flag of
# docs/service.md §5), --version prints the version the build compiled in ($BUILD/version.stamp,
# which the Makefile keeps), --opt=value and --opt value both work (a server started with
# --lease-seconds=7 gives 7 s leases, over a config file's 9; the token commands take
# --state=DIR), and a bad command line exits 2 naming what is wrong, with a hint.
#   bash tests/service/options_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP
worker_pid=""
trap '[ -n "$worker_pid" ] && kill -TERM "$worker_pid" 2>/dev/null; svc_cleanup' EXIT
version=$(cat "$build/version.stamp" 2>/dev/null)

for prog in poro-server poro-worker; do
	"$build/$prog" --help > "$tmp/$prog.help" 2> "$tmp/$prog.help.err"
	rc=$?
	[ "$rc" = 0 ] && [ ! -s "$tmp/$prog.help.err" ] && grep -q "^usage: $prog " "$tmp/$prog.help"
	check "${prog//-/_}_help_exit_0_on_stdout" $? "exit $rc: $(head -3 "$tmp/$prog.help") $(head -2 "$tmp/$prog.help.err")"
	out=$("$build/$prog" --version 2>&1)
	rc=$?
	[ "$rc" = 0 ] && [ -n "$version" ] && [ "$out" = "$prog $version" ]
	check "${prog//-/_}_version_is_the_build_version" $? "exit $rc: '$out', build version '$version'"
	"$build/$prog" --frobnicate > "$tmp/bad.out" 2> "$tmp/bad.err"
	rc=$?
	[ "$rc" = 2 ] && grep -q "^$prog: unknown option '--frobnicate'" "$tmp/bad.err" &&
		grep -q "Try '$prog --help'" "$tmp/bad.err" && [ ! -s "$tmp/bad.out" ]
	check "${prog//-/_}_unknown_option_exit_2" $? "exit $rc: $(cat "$tmp/bad.err")"
	last=--listen
	[ "$prog" = poro-worker ] && last=--name
	"$build/$prog" "$last" > /dev/null 2> "$tmp/bad.err"   # the last option, without its value
	rc=$?
	[ "$rc" = 2 ] && grep -q "option '$last' needs a value" "$tmp/bad.err"
	check "${prog//-/_}_option_without_value_exit_2" $? "exit $rc: $(cat "$tmp/bad.err")"
done
[ "$version" != unknown ]
check build_version_from_git $? "version '$version'"

# every flag of the server's table in docs/service.md §5 is in --help, and nothing else is
why=$(python3 - docs/service.md "$tmp/poro-server.help" <<'PY'
import re, sys
doc = open(sys.argv[1]).read()
table = doc[doc.index("## 5. Configuration"):]
table = table[:table.index("\n\n", table.index("| flag |"))]
documented = set(re.findall(r"^\| `--([a-z-]+)`", table, re.M))
helped = set(re.findall(r"^  --([a-z-]+)=", open(sys.argv[2]).read(), re.M)) - {"config"}
missing, extra = sorted(documented - helped), sorted(helped - documented)
if missing or extra:
    print("documented but not in --help: %s; in --help but not documented: %s" % (missing, extra))
    sys.exit(1)
PY
)
check server_help_lists_every_documented_flag $? "$why"
for flag in server token-file token slots threads work solver memory-limit-mb checkpoint-wall lease-renew name keep-work; do
	grep -q -- "--$flag=" "$tmp/poro-worker.help" || missing_worker="${missing_worker:-} $flag"
done
[ -z "${missing_worker:-}" ]
check worker_help_lists_every_option $? "missing:${missing_worker:-}"

# ---- --opt=value ----------------------------------------------------------------------------------
"$build/poro-server" --lease-seconds=x > /dev/null 2> "$tmp/bad.err"
rc=$?
[ "$rc" = 2 ] && grep -q "'lease-seconds' must be an integer in 1..86400, got 'x'" "$tmp/bad.err"
check server_bad_value_exit_2 $? "exit $rc: $(cat "$tmp/bad.err")"
"$build/poro-server" --listen=127.0.0.1:0 stray > /dev/null 2> "$tmp/bad.err"
rc=$?
[ "$rc" = 2 ] && grep -q "unexpected argument 'stray'" "$tmp/bad.err"
check server_stray_argument_exit_2 $? "exit $rc: $(cat "$tmp/bad.err")"

state="$tmp/eq"
mkdir -p "$state"
printf 'lease-seconds = 9\nmax-attempts = 3\n' > "$tmp/server.conf"
"$build/poro-server" --config="$tmp/server.conf" --listen=127.0.0.1:0 --state="$state" --lease-seconds=7 \
	> "$tmp/eq.out" 2> "$tmp/eq.err" &
SVC_PIDS[eq]=$!
SVC_STATES[eq]=$state
wait_for 10 test -s "$state/server.url"
check server_starts_with_opt_equals_value $? "$(cat "$tmp/eq.err")"
SVC_URLS[eq]=$(cat "$state/server.url")
svc_use eq
alice=$("$build/poro-server" token create --state="$state" --user=alice --role=user)
svc_record_token "$alice"
pool=$("$build/poro-server" token create --state "$state" --user=pool --role=worker)
svc_record_token "$pool"
[ ${#alice} -eq 48 ] && [ ${#pool} -eq 48 ]
check token_create_with_opt_equals_value $? "got ${#alice} and ${#pool} characters"
python3 -c 'import json; json.dump({"case": json.load(open("tests/cases/terzaghi.json"))}, open("'"$tmp"'/case.json", "w"))'
svc_req POST /v1/jobs "$alice" -H 'Content-Type: application/json' --data-binary "@$tmp/case.json" > /dev/null
job=$(json '["id"]' < "$SVC_BODY")
code=$(svc_req POST /v1/worker/claim "$pool" -d '{"worker": "probe", "wait_seconds": 5}')
[ "$code" = 200 ] && [ "$(json '["job"]["lease_seconds"]' < "$SVC_BODY")" = 7 ]
check opt_equals_value_wins_over_config_file $? "status $code: lease_seconds $(json '["job"]["lease_seconds"]' < "$SVC_BODY")"
svc_req POST "/v1/worker/jobs/$job/finish" "$pool" -d '{"attempt": 1, "outcome": "cancelled"}' > /dev/null

# the worker: --opt=value throughout; its start line names what it was given
(umask 077 && printf '%s\n' "$pool" > "$tmp/pool.token")
"$build/poro-worker" --server="$SVC_URL" --token-file="$tmp/pool.token" --name=opt-worker --slots=2 --threads=4 \
	--work="$tmp/work" --solver="$build/poro-solve" --memory-limit-mb=0 --keep-work=no > "$tmp/worker.log" 2>&1 &
worker_pid=$!
started() { grep -q "opt-worker serving $SVC_URL with 2 slots of 2 threads (--threads 4), no memory limit (--memory-limit-mb 0)" "$tmp/worker.log"; }
wait_for 10 started
check worker_opt_equals_value $? "$(head -3 "$tmp/worker.log")"
kill -TERM "$worker_pid"
wait "$worker_pid"
rc=$?
worker_pid=""
[ "$rc" = 0 ]
check worker_drains_exit_0 $? "exit $rc: $(tail -2 "$tmp/worker.log")"
svc_stop eq
check server_stops_exit_0 "$SVC_STATUS" "exit $SVC_STATUS"
