#!/usr/bin/env bash
# tls_test.sh - the server and a worker on different hosts, talking over TLS (docs/operations.md,
# "TLS"). The test makes two network namespaces joined by a veth pair (ip netns, run as root), a
# certificate authority and a server certificate for the server's address (openssl), then:
#   - a server refuses plain HTTP on the non-loopback address unless --allow-plain-http=1;
#   - a worker and the poro CLI in the other namespace, given the CA file, reach the server's
#     --tls-listen address over the veth, and a submitted job runs to success there;
#   - a worker given another CA stops with a message naming the CA file, and never claims;
#   - a worker given an http:// URL of that address is refused before it sends its token;
#   - the CLI with the wrong CA is refused with the same message; a plain client on the TLS port
#     gets no answer.
# Without the right to make network namespaces (not root, a container without CAP_NET_ADMIN) it
# says so on an INFO line and checks nothing, except under CI=1, where that is a failure.
#   bash tests/service/tls_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
root=$PWD
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP

# names and a /24 of our own, so that tests running side by side on one machine never meet
tag=$$
ns_server="poro-tls-s-$tag" ns_worker="poro-tls-w-$tag"
net="10.$((200 + tag % 50)).$(((tag / 50) % 250))"
server_ip="$net.1" worker_ip="$net.2"
pids=()
cleanup_tls() {
	local p
	for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null; done
	for p in "${pids[@]}"; do wait "$p" 2>/dev/null; done
	svc_cleanup
	ip netns del "$ns_server" 2>/dev/null
	ip netns del "$ns_worker" 2>/dev/null
}
trap cleanup_tls EXIT

make_namespaces() {
	ip netns add "$ns_server" && ip netns add "$ns_worker" &&
		ip link add "pts$tag" type veth peer name "ptw$tag" &&
		ip link set "pts$tag" netns "$ns_server" && ip link set "ptw$tag" netns "$ns_worker" &&
		ip -n "$ns_server" addr add "$server_ip/24" dev "pts$tag" &&
		ip -n "$ns_worker" addr add "$worker_ip/24" dev "ptw$tag" &&
		ip -n "$ns_server" link set "pts$tag" up && ip -n "$ns_worker" link set "ptw$tag" up &&
		ip -n "$ns_server" link set lo up && ip -n "$ns_worker" link set lo up
}
if ! make_namespaces 2> "$tmp/netns.err"; then
	if [ -n "${CI:-}" ]; then
		check network_namespaces_available 1 "cannot make network namespaces under CI: $(cat "$tmp/netns.err")"
	else
		echo "INFO tls test skipped: cannot make network namespaces here ($(head -1 "$tmp/netns.err")); it runs as root"
	fi
	svc_summary
	exit 0
fi
in_server() { ip netns exec "$ns_server" "$@"; }
in_worker() { ip netns exec "$ns_worker" "$@"; }
in_worker ip route get "$server_ip" | grep -q "dev ptw$tag"
check namespaces_joined_by_veth $? "the worker's namespace has no route to $server_ip over the veth"

# ---- a certificate authority, a server certificate for the server's address, another CA -------
pki=$tmp/pki
mkdir -p "$pki"
make_ca() { # NAME
	openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:P-256 -nodes -days 2 -subj "/CN=$1" \
		-keyout "$pki/$1.key" -out "$pki/$1.pem" 2>> "$pki/openssl.err"
}
make_ca lab-ca && make_ca other-ca &&
	openssl req -newkey ec -pkeyopt ec_paramgen_curve:P-256 -nodes -subj "/CN=poro-server" \
		-keyout "$pki/server.key" -out "$pki/server.csr" 2>> "$pki/openssl.err" &&
	printf 'subjectAltName=IP:%s\n' "$server_ip" > "$pki/san.cnf" &&
	openssl x509 -req -in "$pki/server.csr" -CA "$pki/lab-ca.pem" -CAkey "$pki/lab-ca.key" -CAcreateserial \
		-days 2 -extfile "$pki/san.cnf" -out "$pki/server.pem" 2>> "$pki/openssl.err"
check test_pki_made $? "openssl: $(cat "$pki/openssl.err")"

# ---- plain HTTP on a network address is refused unless asked for ------------------------------
in_server "$build/poro-server" --listen "$server_ip:0" --state "$tmp/plain" > /dev/null 2> "$tmp/plain.err"
status=$?
check plain_http_on_network_refused "$([ "$status" = 1 ] && grep -q "refusing plain HTTP on --listen '$server_ip:0'" "$tmp/plain.err"; echo $?)" \
	"exit $status: $(tail -2 "$tmp/plain.err")"
SVC_WRAP=(ip netns exec "$ns_server")
svc_start plain --listen "$server_ip:0" --allow-plain-http 1 2> /dev/null
check plain_http_when_allowed $? "--allow-plain-http=1 did not let the server start"
svc_stop plain

# ---- the server: plain on its own loopback, TLS on the veth -----------------------------------
svc_start main --lease-seconds 5 --tls-listen "$server_ip:0" --tls-cert "$pki/server.pem" --tls-key "$pki/server.key"
check tls_server_starts $? "$(tail -3 "$tmp/main.err")"
tls_url=$(cat "$SVC_STATE/server-tls.url" 2>/dev/null)
code=$(in_worker curl -s -o /dev/null -w '%{http_code}' --max-time 3 "$SVC_URL/healthz")
check server_loopback_not_reachable_from_worker "$([ "$code" = 000 ]; echo $?)" "the worker's namespace reached the server's $SVC_URL (HTTP $code): not two hosts"
check tls_url_written "$([[ "$tls_url" == https://$server_ip:* ]]; echo $?)" "server-tls.url holds '$tls_url'"
worker_token=$(svc_token main pilot worker)
user_token=$(svc_token main alice user)
(umask 077 && echo "$worker_token" > "$tmp/worker.token")

python3 - "$root/tests/cases/terzaghi.json" "$tmp/short.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = 0.02
json.dump(c, open(sys.argv[2], "w"))
PY

# ---- the CLI and a worker in the other namespace, over TLS ------------------------------------
poro() { # CA_FILE ARGS...: the poro CLI in the worker's namespace, against the TLS URL
	local ca=$1
	shift
	in_worker env PORO_SERVER="$tls_url" PORO_TOKEN="$user_token" PORO_CA_FILE="$ca" "$build/poro" "$@"
}
id=$(poro "$pki/lab-ca.pem" submit "$tmp/short.json" 2> "$tmp/submit.err")
check cli_submits_over_tls "$([[ "$id" =~ ^[0-9]+$ ]]; echo $?)" "poro submit: '$id' $(cat "$tmp/submit.err")"
# not through in_worker: a backgrounded function is a subshell, and its pid is not the worker's, so
# the TERM below would stop the subshell and leave the worker running (ip netns exec execs the
# command in its own process)
ip netns exec "$ns_worker" "$build/poro-worker" --server "$tls_url" --token-file "$tmp/worker.token" \
	--ca-file "$pki/lab-ca.pem" --work "$tmp/work" --name remote:1 --threads 1 > "$tmp/worker.log" 2>&1 &
pids+=($!)
poro "$pki/lab-ca.pem" wait "$id" > /dev/null 2> "$tmp/wait.err"
status=$?
check job_runs_on_the_remote_worker "$status" "poro wait exit $status: $(tail -3 "$tmp/wait.err"); worker: $(tail -3 "$tmp/worker.log")"
grep -q "route=/v1/worker/claim status=200 .*client=$worker_ip" "$tmp/main.err"
check claim_came_across_the_network $? "no claim from $worker_ip in the server's log"
kill -TERM "${pids[-1]}"; wait "${pids[-1]}"
pgrep -f -- "--work $tmp/work " > /dev/null   # this run's worker, by its own work directory
check remote_worker_stops_on_term $(( $? == 0 )) "the worker still runs: $(pgrep -fa -- "--work $tmp/work ")"

# ---- refusals ---------------------------------------------------------------------------------
in_worker timeout 30 "$build/poro-worker" --server "$tls_url" --token-file "$tmp/worker.token" --ca-file "$pki/other-ca.pem" \
	--work "$tmp/work2" --name wrong-ca:1 > "$tmp/wrong.log" 2>&1
status=$?
check worker_with_wrong_ca_stops "$([ "$status" = 1 ] && grep -q "server not trusted, stopping: cannot verify the server's TLS certificate against the CA file '$pki/other-ca.pem'" "$tmp/wrong.log"; echo $?)" \
	"exit $status: $(tail -3 "$tmp/wrong.log")"
grep -q "worker=wrong-ca:1" "$tmp/main.err"
check worker_with_wrong_ca_never_claims "$([ $? -ne 0 ]; echo $?)" "the server saw a claim of wrong-ca:1"
in_worker timeout 30 "$build/poro-worker" --server "http://$server_ip:${tls_url##*:}" --token-file "$tmp/worker.token" \
	--work "$tmp/work3" > "$tmp/plain-worker.log" 2>&1
status=$?
check worker_with_plain_url_refused "$([ "$status" = 2 ] && grep -q "refusing plain HTTP to '$server_ip'" "$tmp/plain-worker.log"; echo $?)" \
	"exit $status: $(tail -3 "$tmp/plain-worker.log")"
poro "$pki/other-ca.pem" ls > /dev/null 2> "$tmp/cli-wrong.err"
status=$?
check cli_with_wrong_ca_refused "$([ "$status" != 0 ] && grep -q "cannot verify the server's TLS certificate against the CA file '$pki/other-ca.pem'" "$tmp/cli-wrong.err"; echo $?)" \
	"exit $status: $(cat "$tmp/cli-wrong.err")"
code=$(in_worker curl -s -o /dev/null -w '%{http_code}' --max-time 5 "http://$server_ip:${tls_url##*:}/healthz")
check plain_request_to_tls_port_unanswered "$([ "$code" = 000 ]; echo $?)" "a plain request to the TLS port got HTTP $code"
svc_stop main
check server_stops_cleanly "$SVC_STATUS" "exit $SVC_STATUS"
svc_summary
