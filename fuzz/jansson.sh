#!/usr/bin/env bash
# fuzz/jansson.sh OUT CC CFLAGS - builds jansson with the fuzzers' instrumentation into OUT
# (OUT/include/jansson.h, OUT/lib/libjansson.a), from the source of the very version installed
# (Debian's libjansson4), fetched with apt-get source.
#
# Why: Debian's libjansson is built without coverage instrumentation, so a fuzzer linked with it
# sees nothing of jansson's parser, the code every request body and case goes through first.
# The source is fetched through apt with a private list of Debian source archives (deb-src of the
# same archive and release the system's apt lists name), kept in OUT/apt: the system's apt
# configuration is not changed. Nothing of jansson is kept in the repository.
#
# Exits 0 with OUT/lib/libjansson.a, or 1 saying why not (no deb-src reachable, no dpkg-source);
# fuzz/fuzz.mk then links Debian's uninstrumented library and says so.
set -euo pipefail
out=$1 cc=$2 cflags=$3
mkdir -p "$out" && out=$(cd "$out" && pwd)   # apt takes a relative path as under /etc/apt
[ -f "$out/lib/libjansson.a" ] && exit 0
version=$(dpkg-query -W -f='${source:Version}' libjansson4 2>/dev/null || true)
[ -n "$version" ] || { echo "fuzz: libjansson4 is not installed" >&2; exit 1; }
command -v dpkg-source >/dev/null || { echo "fuzz: dpkg-source (dpkg-dev) is missing" >&2; exit 1; }

# The archive and release of the system's own Debian lists (deb822 or one-line form).
uri="" suite=""
if [ -f /etc/apt/sources.list.d/debian.sources ]; then
	uri=$(awk '/^URIs:/ { print $2; exit }' /etc/apt/sources.list.d/debian.sources)
	suite=$(awk '/^Suites:/ { print $2; exit }' /etc/apt/sources.list.d/debian.sources)
fi
if [ -z "$uri" ] && [ -f /etc/apt/sources.list ]; then
	read -r uri suite < <(awk '$1 == "deb" && $2 !~ /security/ { print $2, $3; exit }' /etc/apt/sources.list) || true
fi
[ -n "$uri" ] && [ -n "$suite" ] || { echo "fuzz: no Debian archive found in the apt sources" >&2; exit 1; }

apt="$out/apt"
mkdir -p "$apt/lists/partial" "$out/src"
echo "deb-src $uri $suite main" > "$apt/sources.list"
opts=(-o Dir::Etc::SourceList="$apt/sources.list" -o Dir::Etc::SourceParts=/nonexistent
      -o Dir::State::Lists="$apt/lists" -o APT::Sandbox::User=root -qq)
echo "fuzz: fetching jansson $version's source (deb-src $uri $suite)"
apt-get "${opts[@]}" update >&2 || { echo "fuzz: apt-get update of deb-src $uri failed" >&2; exit 1; }
(cd "$out/src" && apt-get "${opts[@]}" source --download-only "jansson=$version" >&2) ||
	{ echo "fuzz: apt-get source jansson=$version failed" >&2; exit 1; }
rm -rf "$out/src/jansson"
dpkg-source -q -x "$out/src"/jansson_*.dsc "$out/src/jansson" >&2

# jansson's build normally generates two headers (cmake or autoconf); their values for Linux are
# fixed, so they are written here and the library is compiled directly.
s="$out/src/jansson/src"
sed -e 's/@json_inline@/inline/' -e 's/@json_have_long_long@/1/' -e 's/@json_have_localeconv@/1/' \
    -e 's/@json_have_atomic_builtins@/1/' -e 's/@json_have_sync_builtins@/1/' \
    "$s/jansson_config.h.in" > "$s/jansson_config.h"
cat > "$s/jansson_private_config.h" <<'H'
#define HAVE_STDINT_H 1
#define HAVE_FCNTL_H 1
#define HAVE_UNISTD_H 1
#define HAVE_SYS_TYPES_H 1
#define HAVE_SYS_STAT_H 1
#define HAVE_SYS_TIME_H 1
#define HAVE_SCHED_H 1
#define HAVE_CLOSE 1
#define HAVE_GETPID 1
#define HAVE_GETTIMEOFDAY 1
#define HAVE_OPEN 1
#define HAVE_READ 1
#define HAVE_SCHED_YIELD 1
#define HAVE_LOCALECONV 1
#define HAVE_ATOMIC_BUILTINS 1
#define HAVE_SYNC_BUILTINS 1
#define USE_URANDOM 1
#define INITIAL_HASHTABLE_ORDER 3
H
mkdir -p "$out/obj" "$out/lib" "$out/include"
objs=()
for f in "$s"/*.c; do
	o="$out/obj/$(basename "$f" .c).o"
	# shellcheck disable=SC2086
	$cc $cflags -DHAVE_CONFIG_H -I"$s" -c "$f" -o "$o"
	objs+=("$o")
done
ar rcs "$out/lib/libjansson.a" "${objs[@]}"
cp "$s/jansson.h" "$s/jansson_config.h" "$out/include/"
echo "fuzz: built jansson $version with coverage instrumentation in $out/lib/libjansson.a"
