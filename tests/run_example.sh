#!/usr/bin/env bash
# What `make run` does after building: brings the service up on this machine with its embedded
# defaults (poro-server on 127.0.0.1:8080 with its SQLite file and result store under ./var, one
# poro-worker), submits the Terzaghi example (tests/cases/terzaghi.json) through the poro CLI,
# waits for it with a progress bar, fetches result.h5 and result.xdmf into runs/terzaghi, prints
# their paths and the error of the last frame against Terzaghi's closed form, and then keeps the
# service running until Ctrl-C (which drains the worker and stops the server).
#
# Tokens are created once and kept in var/tokens/ (user.token, worker.token; mode 600), so later
# runs reuse them; `export PORO_SERVER=... PORO_TOKEN=$(cat var/tokens/user.token)` lets the poro
# CLI and curl talk to the same service. The worker reads its token from its file (--token-file),
# so no token appears in the process list. PORO_LISTEN overrides the address (HOST:PORT).
#   tests/run_example.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/.."
listen=${PORO_LISTEN:-127.0.0.1:8080}
state=var
mkdir -p "$state/tokens" runs || exit 4
chmod 700 "$state/tokens"
chmod 600 "$state"/tokens/*.token 2>/dev/null   # poro-worker refuses a token file others may read

server_pid=""
worker_pid=""
stop() {
	[ -n "$worker_pid" ] && kill -TERM "$worker_pid" 2>/dev/null && wait "$worker_pid" 2>/dev/null
	[ -n "$server_pid" ] && kill -TERM "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null
	worker_pid=""
	server_pid=""
}
trap 'stop; exit 0' INT TERM
trap stop EXIT

token() { # ROLE: the saved token of that role, created on first use
	local file="$state/tokens/$1.token"
	if [ ! -s "$file" ]; then
		(umask 077 && "$build/poro-server" token create --state "$state" --user "lab-$1" --role "$1" \
			| tail -1 > "$file") || return 1
	fi
	cat "$file"
}

user_token=$(token user) && token worker > /dev/null || { echo "run_example: cannot create tokens in $state" >&2; exit 4; }

rm -f "$state/server.url"
"$build/poro-server" --listen "$listen" --state "$state" > "$state/server.log" 2>&1 &
server_pid=$!
for i in $(seq 100); do
	[ -s "$state/server.url" ] && break
	if ! kill -0 "$server_pid" 2>/dev/null; then
		echo "run_example: poro-server did not start (is $listen in use? set PORO_LISTEN=HOST:PORT):" >&2
		tail -3 "$state/server.log" >&2
		server_pid=""
		exit 1
	fi
	sleep 0.1
done
url=$(cat "$state/server.url")
"$build/poro-worker" --server "$url" --token-file "$state/tokens/worker.token" --work "$state/work" --solver "$build/poro-solve" \
	> "$state/worker.log" 2>&1 &
worker_pid=$!

export PORO_SERVER=$url PORO_TOKEN=$user_token
echo "service: $url (state in $state/, logs $state/server.log and $state/worker.log)"
id=$("$build/poro" submit tests/cases/terzaghi.json --wait --name terzaghi-example)
status=$?
if [ "$status" -ne 0 ] || [ -z "$id" ]; then
	echo "run_example: the Terzaghi example did not succeed (poro submit exit $status)" >&2
	exit 1
fi
rm -rf runs/terzaghi
"$build/poro" fetch "$id" --out runs/terzaghi || exit 1
dir=$(cd runs/terzaghi && pwd)
echo
echo "job $id succeeded"
echo "results:  $dir/result.h5"
echo "ParaView: $dir/result.xdmf"
"$build/terzaghi-error" runs/terzaghi || exit 1
echo
echo "The dashboard: $url/ (sign in with the token in $state/tokens/user.token)"
echo "The service keeps running; Ctrl-C stops it. From another shell:"
echo "  export PORO_SERVER=$url PORO_TOKEN=\$(cat $PWD/$state/tokens/user.token)"
echo "  $build/poro submit tests/cases/xie_leo.json --wait"
wait "$server_pid"
