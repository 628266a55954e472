#!/usr/bin/env bash
# The dashboard at 100,000 jobs (run by bench/list.sh on the server it seeded), printed and never
# asserted: latency percentiles of the jobs search as the jobs page asks it (GET /v1/jobs with the
# dashboard's filters, one client, WEB_REQUESTS each), then Debian's chromium, driven by
# playwright-core (tests/web), opening the jobs page and paging through it: the time from the
# navigation to the rows shown, and the longest task the page ran (the browser's "long task"
# entries: a page that froze would show one as long as the freeze).
#   WEB_URL=... WEB_ADMIN=TOKEN WEB_USER=TOKEN WEB_SMALL=NAME bash bench/web.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/.."
REQUESTS=${WEB_REQUESTS:-200}
load() { "$build/poro-load" get --server "$WEB_URL" --clients 1 --count "$REQUESTS" "$@" | sed 's/ per second; latency/ per second;/'; }
today=$(date -u +%Y-%m-%d)
search() { # NAME TOKEN PATH
	echo "$1: $(load --token "$2" --path "$3")"
}
search "search, title matching every job, page of 100" "$WEB_USER" "/v1/jobs?title=terzaghi&limit=100"
search "search, label matching none (every index entry read)" "$WEB_USER" "/v1/jobs?name=no-such-label&limit=100"
search "search, admin, title matching none of 100,000" "$WEB_ADMIN" "/v1/jobs?title=no-such-case&limit=100"
search "search, created today, page of 100" "$WEB_USER" "/v1/jobs?created_after=$today&created_before=$today&limit=100"
search "search, oldest first, page of 100" "$WEB_USER" "/v1/jobs?order=oldest&limit=100"
search "search, state=succeeded and title, page of 100" "$WEB_USER" "/v1/jobs?state=succeeded&title=terzaghi&limit=100"
search "search, admin, user with 10 jobs" "$WEB_ADMIN" "/v1/jobs?user=$WEB_SMALL&limit=100"
if [ -x /usr/bin/chromium ] && [ -f tests/web/node_modules/playwright-core/package.json ]; then
	node tests/web/render_bench.mjs
else
	echo "jobs page in chromium: not measured (/usr/bin/chromium or playwright-core missing: deploy/deps.sh)"
fi
