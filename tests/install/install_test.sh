#!/usr/bin/env bash
# install_test.sh - `make install DESTDIR=$tmp PREFIX=/usr` and `make uninstall` (docs/service.md §9).
#
# Installs into a temporary root and checks: exactly the expected files, with their modes (the
# five programs; the four systemd units (server, worker, the benchmark nightly's service and
# timer) with their paths filled in; the sysusers.d account; the
# schemas; the five man pages with the version set; the bash completions of poro and poro-solve;
# the configuration); the installed programs run; every man page renders with `man -l` without a
# warning, and the poro-server and poro-worker pages name every option their --help lists; each
# completion file sources cleanly in a plain bash (set -eu, no bash-completion) and completes
# subcommands and options; `systemd-analyze verify` passes on the installed units (a unit's
# programs and man pages are looked up in the installed root), and `systemd-analyze security
# --offline=true` rates them (recorded, and held below EXPOSURE_MAX); an operator's changed
# configuration survives a second install; `make uninstall` leaves only the configuration.
# The make variables of the make running this test are cleared: make is started as by a user.
#   bash tests/install/install_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
unset MAKEFLAGS MFLAGS MAKELEVEL MAKEOVERRIDES
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
root="$tmp/root"
EXPOSURE_MAX=2.0   # systemd-analyze security's scale: 0 (locked down) .. 10; 1.1 and 1.2 when written

check() { # name, condition exit status (0 = holds), why
	if [ "$2" -eq 0 ]; then echo "PASS $1"; else echo "FAIL $1: $3"; fi
}

make install DESTDIR="$root" PREFIX=/usr BUILD="$build" > "$tmp/install.txt" 2>&1
rc=$?
check make_install_exits_0 $rc "$(tail -5 "$tmp/install.txt")"

# ---- the files --------------------------------------------------------------------------------------
cat > "$tmp/want.txt" <<'EOF'
755 etc/poro
644 etc/poro/poro-server.conf
755 usr/bin/poro
755 usr/bin/poro-plot
755 usr/bin/poro-server
755 usr/bin/poro-solve
755 usr/bin/poro-worker
644 usr/lib/systemd/system/poro-nightly.service
644 usr/lib/systemd/system/poro-nightly.timer
644 usr/lib/systemd/system/poro-server.service
644 usr/lib/systemd/system/poro-worker@.service
644 usr/lib/sysusers.d/poro.conf
644 usr/share/bash-completion/completions/poro
644 usr/share/bash-completion/completions/poro-solve
644 usr/share/man/man1/poro-plot.1
644 usr/share/man/man1/poro-server.1
644 usr/share/man/man1/poro-solve.1
644 usr/share/man/man1/poro-worker.1
644 usr/share/man/man1/poro.1
644 usr/share/poro/examples/poro-server.conf
644 usr/share/poro/examples/worker.env
644 usr/share/poro/schemas/case.schema.json
644 usr/share/poro/schemas/element.schema.json
644 usr/share/poro/schemas/metrics.schema.json
644 usr/share/poro/schemas/openapi.yaml
644 usr/share/poro/schemas/results.md
644 usr/share/poro/schemas/suite.schema.json
EOF
[ -d web ] && (cd web && find -L . -type f | sed 's|^\./|644 usr/share/poro/web/|') >> "$tmp/want.txt"
# every file, and the directories of etc/ (an installed directory of its own there)
(cd "$root" && { find . -type f; find ./etc -mindepth 1 -type d; } | sed 's|^\./||' | sort |
	while read -r f; do echo "$(stat -c %a "$f") $f"; done) > "$tmp/got.txt"
sort -k2 "$tmp/want.txt" -o "$tmp/want.txt"
diff "$tmp/want.txt" "$tmp/got.txt" > "$tmp/files.diff"
check install_puts_exactly_the_expected_files $? "$(head -20 "$tmp/files.diff")"

"$root/usr/bin/poro-server" --version > "$tmp/v.txt" 2>&1 && "$root/usr/bin/poro-worker" --version >> "$tmp/v.txt" 2>&1 &&
	[ "$(cat "$tmp/v.txt")" = "poro-server $(cat "$build/version.stamp")
poro-worker $(cat "$build/version.stamp")" ]
check installed_programs_run $? "$(cat "$tmp/v.txt")"

units="$root/usr/lib/systemd/system"
grep -q '^ExecStart=/usr/bin/poro-server --config=/etc/poro/poro-server.conf ' "$units/poro-server.service" &&
	grep -q '^ExecStart=/usr/bin/poro-worker .*--solver=/usr/bin/poro-solve' "$units/poro-worker@.service" &&
	grep -q '^ExecStart=/usr/bin/poro nightly run ' "$units/poro-nightly.service" &&
	! grep -q '@[a-z]*@' "$units"/*.service
check units_name_the_installed_programs $? "$(grep -h '^ExecStart\|@[a-z]*@' "$units"/*.service)"

# ---- man pages ----------------------------------------------------------------------------------
man_ok=0
for page in "$root"/usr/share/man/man1/*.1; do
	name=$(basename "$page" .1)
	LC_ALL=C.UTF-8 MANWIDTH=100 man --warnings -l "$page" > "$tmp/$name.man" 2> "$tmp/$name.man.err"
	rc=$?
	if [ "$rc" -ne 0 ] || [ -s "$tmp/$name.man.err" ] || ! grep -q "^NAME" "$tmp/$name.man" ||
		! grep -q "^       $name - " "$tmp/$name.man" || ! grep -q "PoroMPM $(cat "$build/version.stamp")" "$tmp/$name.man"; then
		man_ok=1
		echo "INFO man -l $name.1: exit $rc, $(head -c 300 "$tmp/$name.man.err")"
	fi
done
check man_pages_render_with_man_l $man_ok "see the INFO lines above"
for prog in poro-server poro-worker; do
	missing=""
	for opt in $("$root/usr/bin/$prog" --help | grep -oE '^  (-h, )?--[a-z-]+' | grep -oE -- '--[a-z-]+'); do
		grep -qe "$opt" "$tmp/$prog.man" || missing="$missing $opt"
	done
	[ -z "$missing" ]
	check "${prog//-/_}_man_page_names_every_option" $? "not in the page:$missing"
done

# ---- bash completion ------------------------------------------------------------------------------
comp="$root/usr/share/bash-completion/completions"
complete_words() { # FILE FUNCTION WORD...: what the completion offers for the last word
	local file=$1 fn=$2
	shift 2
	bash --norc --noprofile -c '
		set -eu
		. "$1"
		fn=$2; shift 2
		COMP_WORDS=("$@"); COMP_CWORD=$(( $# - 1 )); COMP_LINE="$*"; COMP_POINT=${#COMP_LINE}
		"$fn"
		printf "%s\n" "${COMPREPLY[@]}"' bash "$file" "$fn" "$@"
}
for name in poro poro-solve; do
	out=$(bash --norc --noprofile -c 'set -eu; . "$1"; complete -p "$2"' bash "$comp/$name" "$name" 2>&1)
	rc=$?
	[ "$rc" = 0 ] && [[ "$out" == "complete "*"-F "*" $name" ]]
	check "completion_${name//-/_}_sources_cleanly" $? "exit $rc: $out"
done
mkdir -p "$tmp/cases/sub" && touch "$tmp/cases/slope.json" "$tmp/cases/notes.txt"
[ "$(complete_words "$comp/poro" _poro poro su)" = submit ] &&
	[ "$(complete_words "$comp/poro" _poro poro submit --wai)" = --wait ] &&
	[ "$(complete_words "$comp/poro" _poro poro ls --state queued,ru)" = queued,running ] &&
	[ "$(complete_words "$comp/poro" _poro poro submit "$tmp/cases/" | sort | tr '\n' ' ')" = "$tmp/cases/slope.json $tmp/cases/sub " ]
check completion_poro_completes $? "su -> '$(complete_words "$comp/poro" _poro poro su)', files -> '$(complete_words "$comp/poro" _poro poro submit "$tmp/cases/" | tr '\n' ' ')'"
[ "$(complete_words "$comp/poro-solve" _poro_solve poro-solve val)" = validate ] &&
	[ "$(complete_words "$comp/poro-solve" _poro_solve poro-solve run case.json --ou)" = --out ] &&
	[ "$(complete_words "$comp/poro-solve" _poro_solve poro-solve probes r.h5 --at)" = --attempt ]
check completion_poro_solve_completes $? "val -> '$(complete_words "$comp/poro-solve" _poro_solve poro-solve val)'"
# the completion offers exactly the commands poro-solve's own usage lists, so a new command cannot
# be left out of it
commands=$("$root/usr/bin/poro-solve" --help | sed -n 's/^\(usage:\|      \) poro-solve \([a-z]\+\).*/\2/p' | sort | tr '\n' ' ')
offered=$(complete_words "$comp/poro-solve" _poro_solve poro-solve '' | sort | tr '\n' ' ')
[ -n "$commands" ] && [ "$commands" = "$offered" ]
check completion_poro_solve_offers_every_command $? "usage lists '$commands', the completion offers '$offered'"

# ---- systemd ----------------------------------------------------------------------------------------
# The units are checked as installed: in a root holding the installation and the system's own
# units (the targets they name), so verify finds the programs of ExecStart there, and with MANPATH
# on the installed pages, so Documentation=man:... must name a page that was installed.
if ! command -v systemd-analyze > /dev/null; then
	check systemd_analyze_installed 1 "no systemd-analyze: deploy/deps.sh installs package systemd"
else
	vroot="$tmp/vroot"
	mkdir -p "$vroot"
	cp -a "$root/." "$vroot/"
	cp -rn /usr/lib/systemd/system/. "$vroot/usr/lib/systemd/system/"
	(cd "$tmp" && MANPATH="$root/usr/share/man" systemd-analyze verify --root="$vroot" poro-server.service \
		poro-worker@1.service poro-nightly.service poro-nightly.timer) > "$tmp/verify.txt" 2>&1
	rc=$?
	[ "$rc" = 0 ] && [ ! -s "$tmp/verify.txt" ]
	check systemd_analyze_verify_installed_units $? "exit $rc: $(head -5 "$tmp/verify.txt")"
	# and it does look: a unit whose program is missing fails
	rm "$vroot/usr/bin/poro-server"
	(cd "$tmp" && MANPATH="$root/usr/share/man" systemd-analyze verify --root="$vroot" poro-server.service) > /dev/null 2>&1
	check systemd_analyze_verify_sees_a_missing_program $(( $? == 0 )) "verify passed without /usr/bin/poro-server"
	cp "$root/usr/bin/poro-server" "$vroot/usr/bin/"
	for unit in poro-server.service poro-worker@1.service poro-nightly.service; do
		(cd "$tmp" && systemd-analyze security --offline=true --root="$vroot" "$unit") > "$tmp/security.txt" 2>&1
		score=$(grep -oE 'Overall exposure level for [^:]+: [0-9.]+' "$tmp/security.txt" | grep -oE '[0-9.]+$')
		echo "INFO systemd-analyze security --offline=true $unit: exposure $score (0 = locked down, 10 = exposed)"
		name=${unit%%[@.]*}
		[ -n "$score" ] && python3 -c "import sys; sys.exit(0 if float('$score') <= $EXPOSURE_MAX else 1)"
		check "security_exposure_${name//-/_}_at_most_$EXPOSURE_MAX" $? "$(grep -E '✗' "$tmp/security.txt" | head -8)"
	done
	grep -q '^NoNewPrivileges=yes' "$units/poro-server.service" && grep -q '^ProtectSystem=strict' "$units/poro-server.service" &&
		grep -q '^StateDirectory=poro$' "$units/poro-server.service" && grep -q '^ReadWritePaths=/var/lib/poro$' "$units/poro-server.service" &&
		grep -q '^PrivateTmp=yes' "$units/poro-server.service" && grep -q '^ProtectHome=yes' "$units/poro-server.service" &&
		grep -q '^RestrictAddressFamilies=AF_INET AF_INET6 AF_UNIX' "$units/poro-server.service" &&
		grep -q '^KillMode=mixed' "$units/poro-worker@.service" && grep -q '^LoadCredential=' "$units/poro-worker@.service"
	check units_hardened_as_documented $? "$(grep -c = "$units/poro-server.service") settings"
fi

# ---- a second install keeps the operator's configuration; uninstall ---------------------------------
echo "lease-seconds = 45" >> "$root/etc/poro/poro-server.conf"
cp "$root/etc/poro/poro-server.conf" "$tmp/conf.before"
make install DESTDIR="$root" PREFIX=/usr BUILD="$build" > "$tmp/install2.txt" 2>&1 &&
	cmp -s "$tmp/conf.before" "$root/etc/poro/poro-server.conf"
check reinstall_keeps_changed_configuration $? "$(tail -3 "$tmp/install2.txt")"
make uninstall DESTDIR="$root" PREFIX=/usr BUILD="$build" > "$tmp/uninstall.txt" 2>&1
rc=$?
left=$(cd "$root" && find . -type f | sed 's|^\./||' | sort | tr '\n' ' ')
[ "$rc" = 0 ] && [ "$left" = "etc/poro/poro-server.conf " ] && grep -q "is left in place" "$tmp/uninstall.txt"
check uninstall_leaves_only_the_configuration $? "exit $rc, left: $left"
