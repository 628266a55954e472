# PoroMPM - one boring Makefile.
#   make run     install what is missing, build what it runs, run the Terzaghi example and report
#                its error
#   make test    unit tests, reduced-size verification, bad-input tests; ends "N passed, N failed"
#   make verify  paper-size verification runs (long)
#   make bench   speed figures (printed, never asserted)
#   make test SAN=1   the same tests under AddressSanitizer + UBSan
#   make test-san     the service's tests alone under AddressSanitizer + UBSan (docs/service.md §6)
#   make install [PREFIX=/usr/local] [DESTDIR=]   programs, systemd units, man pages, completions
#   make uninstall    removes what make install put there
#   make fuzz [FUZZ_SECONDS=180]   the libFuzzer targets of fuzz/, each for FUZZ_SECONDS (fuzz/fuzz.mk)
#   make soak [SOAK_JOBS=10000]    the service under random kills (tests/fault/soak.sh)
# Every public target first runs deploy/deps.sh, which returns at once when nothing is missing.
# They build with one job per core and print one short line per file ("  CC      build/x.o");
# V=1 prints the whole commands instead.

CC      ?= cc
BUILD   ?= build$(if $(SAN),-san)
OPT     ?= -O2
WARN    = -Wall -Wextra -Wshadow -Wno-unused-parameter $(if $(CI),-Werror)
SANITIZERS = -fsanitize=address,undefined -fno-omit-frame-pointer
SANFLAGS = $(if $(SAN),$(SANITIZERS))
PKGS    = jansson hdf5
CPPFLAGS = -D_POSIX_C_SOURCE=200809L -DPORO_VERSION=\"$(VERSION)\" $(addprefix -I,$(SOLVER_DIRS)) -I/usr/include/suitesparse $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
VERSION := $(shell git describe --always --dirty --tags 2>/dev/null || echo unknown)
CFLAGS  = -std=c11 $(OPT) -g -fopenmp $(WARN) $(SANFLAGS)
LDLIBS  = $(shell pkg-config --libs $(PKGS) 2>/dev/null) -lumfpack -lcholmod -lm
LDFLAGS = -fopenmp $(SANFLAGS)

# One line per file unless V=1: $(call quiet,CC) before a command prints "  CC      TARGET" and
# hides the command. The public targets run their build in a sub-make with one job per core,
# unless the caller already gave -j (then its job server is used).
V ?=
quiet = $(if $(filter 1,$(V)),,@printf '  %-7s %s\n' '$(1)' '$@';)
JOBS ?= $(shell nproc 2>/dev/null || echo 1)
SUBMAKE_FLAGS = --no-print-directory $(if $(findstring jobserver,$(MAKEFLAGS)),,-j$(JOBS))

# solver/ (README, "Layout"): the simulation object and its run loop at the top; case/ reads and
# validates a case; material/ the constitutive models; mpm/ the grid, points, shape functions,
# transfers and the phases every scheme shares; schemes/<name>/ each time-integration scheme;
# output/ result files, checkpoints and reports. Every folder is on the include path.
SOLVER_DIRS = $(patsubst %/,%,$(sort $(dir $(wildcard solver/*.h solver/*/*.h solver/*/*/*.h solver/*/*/*.c))))
SOLVER_SRC = $(wildcard solver/*.c solver/*/*.c solver/*/*/*.c)
SOLVER_HDR = $(wildcard solver/*.h solver/*/*.h solver/*/*/*.h)
SOLVER_OBJ = $(SOLVER_SRC:%.c=$(BUILD)/%.o)
LIBPORO    = $(BUILD)/libporo.a
POROSOLVE  = $(BUILD)/poro-solve
TEST_SRC   = $(wildcard tests/solver/*_test.c tests/verify/*_test.c)
TEST_BIN   = $(TEST_SRC:%.c=$(BUILD)/%)
# Tests of common/ (the service's shared code) link that code alone, not the solver.
COMMON_TEST_BIN = $(patsubst %.c,$(BUILD)/%,$(wildcard tests/common/*_test.c))
BENCH_SRC  = $(wildcard bench/*_bench.c)
BENCH_BIN  = $(BENCH_SRC:%.c=$(BUILD)/%)
TOOLS      = $(BUILD)/terzaghi-error $(BUILD)/poro-plot
FAULT_SHIM = $(BUILD)/tests/fault/fault_shim.so

# The service (docs/service.md): server, worker, user CLI and load generator. Each external library
# enters through one file: libmicrohttpd (server/http.c), SQLite (server/store*.c), libcurl
# (client/http_client.c), libcrypto (common/digest.c).
COMMON_OBJ = $(patsubst %.c,$(BUILD)/%.o,$(wildcard common/*.c))
CLIENT_OBJ = $(patsubst %.c,$(BUILD)/%.o,$(wildcard client/*.c))
SERVER_OBJ = $(patsubst %.c,$(BUILD)/%.o,$(wildcard server/*.c))
WORKER_OBJ = $(patsubst %.c,$(BUILD)/%.o,$(wildcard worker/*.c))
SVC_LIBS   = -ljansson -lcrypto -lpthread -lm
# poro-server links libporo.a for case validation only, and never HDF5: it does not read result files
# (probes come from `poro-solve probes`, run by the worker), so a damaged file cannot crash it.
# tests/service/integrity_test.sh checks with ldd that no libhdf5 is linked.
SERVER_LIBS = -lmicrohttpd -lsqlite3 -lm $(SVC_LIBS)
SERVICE    = $(if $(SERVER_OBJ),$(BUILD)/poro-server) $(if $(WORKER_OBJ),$(BUILD)/poro-worker) \
	     $(if $(CLIENT_OBJ),$(BUILD)/poro $(BUILD)/poro-load)

.PHONY: FORCE all deps run test test-san verify bench soak clean build-all build-run build-service format install \
	install-files build-install uninstall
.DEFAULT_GOAL := all
# objects made on the way to a program are kept: deleting them would only rebuild them next time
.PRECIOUS: $(BUILD)/%.o

deps:
	@bash deploy/deps.sh

all: deps
	@$(MAKE) $(SUBMAKE_FLAGS) build-all

build-all: $(POROSOLVE) $(TEST_BIN) $(COMMON_TEST_BIN) $(BENCH_BIN) $(TOOLS) $(SERVICE) $(FAULT_SHIM)

# The fault and power-loss tests' LD_PRELOAD library (tests/fault/fault_shim.c): never sanitized,
# since it is loaded into other programs.
$(FAULT_SHIM): tests/fault/fault_shim.c
	@mkdir -p $(dir $@)
	$(call quiet,CC)$(CC) -std=c11 -D_POSIX_C_SOURCE=200809L $(OPT) -g $(WARN) -fPIC -shared $< -ldl -o $@

# What tests/run_example.sh runs: the server, a worker, the poro CLI, the solver and the error
# against Terzaghi's closed form; no test program.
RUN_BIN = $(POROSOLVE) $(BUILD)/terzaghi-error $(BUILD)/poro-server $(BUILD)/poro-worker $(BUILD)/poro

build-run: $(RUN_BIN)

run: deps
	@$(MAKE) $(SUBMAKE_FLAGS) build-run
	@bash tests/run_example.sh $(BUILD)

test: deps
	@$(MAKE) $(SUBMAKE_FLAGS) build-all
	@bash tests/run.sh $(BUILD) test

# The service's binaries, poro-solve (the workers run it) and the tests of common/: what the
# service tests need, without the solver's test programs.
build-service: $(POROSOLVE) $(COMMON_TEST_BIN) $(SERVICE)

test-san: deps
	@$(MAKE) $(SUBMAKE_FLAGS) SAN=1 build-service
	@bash tests/run.sh build-san service

verify: deps
	@$(MAKE) $(SUBMAKE_FLAGS) build-all
	@bash tests/run.sh $(BUILD) verify

bench: deps
	@$(MAKE) $(SUBMAKE_FLAGS) build-all
	@bash bench/run.sh $(BUILD)

# The soak (docs/hardening.md): SOAK_JOBS short jobs while the server and workers are killed at
# random; make test runs a few hundred of them (tests/fault/soak_test.sh).
SOAK_JOBS ?= 10000
soak: deps
	@$(MAKE) $(SUBMAKE_FLAGS) build-all
	@bash tests/fault/soak.sh $(BUILD) $(SOAK_JOBS)

$(BUILD)/%.o: %.c $(SOLVER_HDR) $(wildcard tests/*.h tests/verify/*.h common/*.h client/*.h server/*.h worker/*.h)
	@mkdir -p $(dir $@)
	$(call quiet,CC)$(CC) $(CPPFLAGS) -Icommon -Iclient $(CFLAGS) -c $< -o $@

# The files that print the version (PORO_VERSION, from git describe) are compiled again when it
# changes, as after a commit: $(BUILD)/version.stamp holds the version they were built with and is
# rewritten only when it differs, so an unchanged version rebuilds nothing.
VERSION_OBJ = $(patsubst %.c,$(BUILD)/%.o,$(shell grep -l PORO_VERSION $(SOLVER_SRC) cli/*.c server/*.c worker/*.c 2>/dev/null))
$(VERSION_OBJ): $(BUILD)/version.stamp
$(BUILD)/version.stamp: FORCE
	@mkdir -p $(dir $@)
	@[ "$$(cat $@ 2>/dev/null)" = "$(VERSION)" ] || echo "$(VERSION)" > $@
FORCE:

$(LIBPORO): $(SOLVER_OBJ)
	@rm -f $@
	$(call quiet,AR)ar rcs $@ $^

$(POROSOLVE): $(BUILD)/cli/poro_solve.o $(LIBPORO)
	$(call quiet,LD)$(CC) $(LDFLAGS) $^ $(LDLIBS) -o $@

$(BUILD)/terzaghi-error: $(BUILD)/tools/terzaghi_error.o $(LIBPORO)
	$(call quiet,LD)$(CC) $(LDFLAGS) $^ $(LDLIBS) -o $@

$(BUILD)/tools/terzaghi_error.o: solver/verify/analytic.h

# poro-plot is a Python program (matplotlib, h5py): "built" by copying it beside poro-solve, which
# it calls for the run-out picture.
$(BUILD)/poro-plot: cli/poro_plot.py
	@mkdir -p $(dir $@)
	$(call quiet,GEN)cp $< $@ && chmod +x $@

$(BUILD)/tests/%: $(BUILD)/tests/%.o $(LIBPORO)
	$(call quiet,LD)$(CC) $(LDFLAGS) $^ $(LDLIBS) -o $@

$(BUILD)/tests/common/%: $(BUILD)/tests/common/%.o $(COMMON_OBJ)
	$(call quiet,LD)$(CC) $(LDFLAGS) $^ $(SVC_LIBS) -o $@

$(BUILD)/bench/%: $(BUILD)/bench/%.o $(LIBPORO)
	$(call quiet,LD)$(CC) $(LDFLAGS) $^ $(LDLIBS) -o $@

$(BUILD)/poro-server: $(SERVER_OBJ) $(COMMON_OBJ) $(LIBPORO)
	$(call quiet,LD)$(CC) $(LDFLAGS) $^ $(SERVER_LIBS) -o $@

$(BUILD)/poro-worker: $(WORKER_OBJ) $(CLIENT_OBJ) $(COMMON_OBJ)
	$(call quiet,LD)$(CC) $(LDFLAGS) $^ -lcurl $(SVC_LIBS) -o $@

# poro: cli/poro.c and its commands in cli/poro/
PORO_CLI_OBJ = $(patsubst %.c,$(BUILD)/%.o,$(wildcard cli/poro/*.c))
$(BUILD)/cli/poro.o $(PORO_CLI_OBJ): $(wildcard cli/poro/*.h)

# poro nightly checks a suite's figures against the solver's own table of them (figures.o, which
# needs nothing else of the solver)
$(BUILD)/poro: $(BUILD)/cli/poro.o $(PORO_CLI_OBJ) $(CLIENT_OBJ) $(COMMON_OBJ) $(BUILD)/solver/verify/figures.o
	$(call quiet,LD)$(CC) $(LDFLAGS) $^ -lcurl $(SVC_LIBS) -lm -o $@

$(BUILD)/poro-load: $(BUILD)/bench/poro_load.o $(CLIENT_OBJ) $(COMMON_OBJ)
	$(call quiet,LD)$(CC) $(LDFLAGS) $^ -lcurl $(SVC_LIBS) -lm -o $@

# make install [PREFIX=/usr/local] [DESTDIR=]: the programs, the systemd units (their @bindir@
# replaced), the account they run as (sysusers.d), the configuration (only when none is there:
# an operator's is never overwritten), the schemas, the man pages (version set), the bash
# completions of poro and poro-solve, and web/ when it exists. make uninstall removes them and
# leaves the configuration. Paths: docs/service.md §9.
PREFIX      ?= /usr/local
BINDIR      ?= $(PREFIX)/bin
DATADIR     ?= $(PREFIX)/share
MANDIR      ?= $(DATADIR)/man
UNITDIR     ?= $(PREFIX)/lib/systemd/system
SYSUSERSDIR ?= $(PREFIX)/lib/sysusers.d
COMPLETIONDIR ?= $(DATADIR)/bash-completion/completions
SYSCONFDIR  ?= /etc
INSTALL_BIN = poro-server poro-worker poro poro-solve poro-plot
UNITS       = $(patsubst deploy/systemd/%.in,%,$(wildcard deploy/systemd/*.in))
MAN_PAGES   = $(notdir $(wildcard docs/man/*.1))
COMPLETIONS = poro poro-solve
SCHEMAS     = $(notdir $(wildcard schemas/*))

build-install: $(addprefix $(BUILD)/,$(INSTALL_BIN))

install: deps
	@$(MAKE) $(SUBMAKE_FLAGS) build-install
	@$(MAKE) --no-print-directory install-files

install-files:
	install -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(UNITDIR) $(DESTDIR)$(SYSUSERSDIR) $(DESTDIR)$(MANDIR)/man1 \
		$(DESTDIR)$(COMPLETIONDIR) $(DESTDIR)$(DATADIR)/poro/schemas $(DESTDIR)$(DATADIR)/poro/examples \
		$(DESTDIR)$(SYSCONFDIR)/poro
	install -m 755 $(addprefix $(BUILD)/,$(INSTALL_BIN)) $(DESTDIR)$(BINDIR)/
	for u in $(UNITS); do \
		sed -e 's|@bindir@|$(BINDIR)|g' -e 's|/etc/poro/|$(SYSCONFDIR)/poro/|g' deploy/systemd/$$u.in > $(DESTDIR)$(UNITDIR)/$$u && \
		chmod 644 $(DESTDIR)$(UNITDIR)/$$u || exit 1; done
	install -m 644 deploy/sysusers.d/poro.conf $(DESTDIR)$(SYSUSERSDIR)/poro.conf
	for m in $(MAN_PAGES); do \
		sed 's|@VERSION@|$(VERSION)|g' docs/man/$$m > $(DESTDIR)$(MANDIR)/man1/$$m && \
		chmod 644 $(DESTDIR)$(MANDIR)/man1/$$m || exit 1; done
	install -m 644 $(addprefix deploy/bash-completion/,$(COMPLETIONS)) $(DESTDIR)$(COMPLETIONDIR)/
	install -m 644 $(addprefix schemas/,$(SCHEMAS)) $(DESTDIR)$(DATADIR)/poro/schemas/
	install -m 644 deploy/poro-server.conf.example $(DESTDIR)$(DATADIR)/poro/examples/poro-server.conf
	install -m 644 deploy/worker.env.example $(DESTDIR)$(DATADIR)/poro/examples/worker.env
	[ -e $(DESTDIR)$(SYSCONFDIR)/poro/poro-server.conf ] || \
		install -m 644 deploy/poro-server.conf.example $(DESTDIR)$(SYSCONFDIR)/poro/poro-server.conf
	if [ -d web ]; then install -d $(DESTDIR)$(DATADIR)/poro/web && cp -RL web/. $(DESTDIR)$(DATADIR)/poro/web/; fi

uninstall:
	rm -f $(addprefix $(DESTDIR)$(BINDIR)/,$(INSTALL_BIN)) $(addprefix $(DESTDIR)$(UNITDIR)/,$(UNITS)) \
		$(DESTDIR)$(SYSUSERSDIR)/poro.conf $(addprefix $(DESTDIR)$(MANDIR)/man1/,$(MAN_PAGES)) \
		$(addprefix $(DESTDIR)$(COMPLETIONDIR)/,$(COMPLETIONS))
	rm -rf $(DESTDIR)$(DATADIR)/poro
	@[ ! -e $(DESTDIR)$(SYSCONFDIR)/poro/poro-server.conf ] || \
		echo "uninstall: $(DESTDIR)$(SYSCONFDIR)/poro/poro-server.conf is left in place (configuration)"

# Formats the lines changed since FORMAT_BASE (default HEAD: the uncommitted work) by .clang-format;
# `make format FORMAT_BASE=origin/main` takes a whole branch. Needs Debian's clang-format.
FORMAT_BASE ?= HEAD
format:
	git clang-format --force $(FORMAT_BASE) -- '*.c' '*.h'

clean:
	rm -rf build build-san build-fuzz

include fuzz/fuzz.mk
