# fuzz/fuzz.mk - libFuzzer targets (docs/hardening.md "Fuzzing"), included by the Makefile.
#   make fuzz [FUZZ_SECONDS=180] [FUZZ_TARGETS="case http"]   runs each target for FUZZ_SECONDS
#   make build-fuzz                                             builds them only
# Built with Debian's clang into build-fuzz/: every object of the solver, common/ and server/
# with coverage instrumentation, AddressSanitizer and UBSan (-fsanitize=fuzzer-no-link), linked
# with libFuzzer; jansson is built from its Debian source the same way (fuzz/jansson.sh), or,
# when that source cannot be had, Debian's uninstrumented library is linked and run.sh says so.
# The packages (clang, libFuzzer, the OpenMP runtime of clang, dpkg-dev) come from
# `deploy/deps.sh fuzz`; make test needs none of them.

FUZZ_BUILD   = build-fuzz
FUZZ_CC      = clang
FUZZ_SAN     = -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
FUZZ_CFLAGS  = -std=c11 -g -O1 -fopenmp $(FUZZ_SAN) -fsanitize=fuzzer-no-link
FUZZ_JANSSON = $(FUZZ_BUILD)/jansson
FUZZ_TARGET_NAMES = $(patsubst fuzz/%_fuzz.c,%,$(wildcard fuzz/*_fuzz.c))
FUZZ_TARGETS ?= $(FUZZ_TARGET_NAMES)
FUZZ_SECONDS ?= 180
FUZZ_BIN     = $(FUZZ_TARGET_NAMES:%=$(FUZZ_BUILD)/fuzz/%_fuzz)

FUZZ_SOLVER_OBJ = $(SOLVER_SRC:%.c=$(FUZZ_BUILD)/%.o)
FUZZ_COMMON_OBJ = $(patsubst %.c,$(FUZZ_BUILD)/%.o,$(wildcard common/*.c))
FUZZ_SERVER_OBJ = $(patsubst %.c,$(FUZZ_BUILD)/%.o,$(wildcard server/*.c))
# Linked with Debian's jansson when fuzz/jansson.sh could not build it (the file says which).
FUZZ_JANSSON_LINK = $$(cat $(FUZZ_JANSSON)/link)

.PHONY: fuzz build-fuzz

fuzz: deps
	@bash deploy/deps.sh fuzz
	@$(MAKE) $(SUBMAKE_FLAGS) build-fuzz $(POROSOLVE)
	@bash fuzz/run.sh $(FUZZ_BUILD) $(BUILD) $(FUZZ_SECONDS) $(FUZZ_TARGETS)

build-fuzz: $(FUZZ_BIN)

$(FUZZ_JANSSON)/link:
	@mkdir -p $(dir $@)
	@if bash fuzz/jansson.sh $(FUZZ_JANSSON) '$(FUZZ_CC)' '-g -O1 $(FUZZ_SAN) -fsanitize=fuzzer-no-link'; then \
		echo $(FUZZ_JANSSON)/lib/libjansson.a > $@; \
	else echo "fuzz: linking Debian's libjansson, which has no coverage instrumentation"; echo -ljansson > $@; fi

$(FUZZ_BUILD)/%.o: %.c $(SOLVER_HDR) $(wildcard common/*.h server/*.h) | $(FUZZ_JANSSON)/link
	@mkdir -p $(dir $@)
	$(call quiet,FUZZCC)$(FUZZ_CC) -I$(FUZZ_JANSSON)/include $(CPPFLAGS) -Icommon -Iclient -Iserver $(FUZZ_CFLAGS) -c $< -o $@

# poro-server's and poro-solve's own main, in process, under another name
$(FUZZ_BUILD)/server/main.o: server/main.c $(wildcard server/*.h common/*.h) | $(FUZZ_JANSSON)/link
	@mkdir -p $(dir $@)
	$(call quiet,FUZZCC)$(FUZZ_CC) -I$(FUZZ_JANSSON)/include $(CPPFLAGS) -Icommon $(FUZZ_CFLAGS) -Dmain=poro_server_main -c $< -o $@
$(FUZZ_BUILD)/cli/poro_solve.o: cli/poro_solve.c $(SOLVER_HDR) | $(FUZZ_JANSSON)/link
	@mkdir -p $(dir $@)
	$(call quiet,FUZZCC)$(FUZZ_CC) -I$(FUZZ_JANSSON)/include $(CPPFLAGS) -Icommon $(FUZZ_CFLAGS) -Dmain=poro_solve_main -c $< -o $@

$(FUZZ_BUILD)/libporo.a: $(FUZZ_SOLVER_OBJ)
	@rm -f $@
	$(call quiet,AR)ar rcs $@ $^

FUZZ_LINK = $(FUZZ_CC) -fopenmp $(FUZZ_SAN) -fsanitize=fuzzer
FUZZ_SOLVER_LIBS = $(shell pkg-config --libs hdf5 2>/dev/null) -lumfpack -lcholmod -lm

$(FUZZ_BUILD)/fuzz/case_fuzz: $(FUZZ_BUILD)/fuzz/case_fuzz.o $(FUZZ_BUILD)/libporo.a
	$(call quiet,LD)$(FUZZ_LINK) $^ $(FUZZ_JANSSON_LINK) $(FUZZ_SOLVER_LIBS) -o $@
$(FUZZ_BUILD)/fuzz/checkpoint_fuzz: $(FUZZ_BUILD)/fuzz/checkpoint_fuzz.o $(FUZZ_BUILD)/libporo.a
	$(call quiet,LD)$(FUZZ_LINK) $^ $(FUZZ_JANSSON_LINK) $(FUZZ_SOLVER_LIBS) -o $@
$(FUZZ_BUILD)/fuzz/results_fuzz: $(FUZZ_BUILD)/fuzz/results_fuzz.o $(FUZZ_BUILD)/cli/poro_solve.o $(FUZZ_BUILD)/libporo.a
	$(call quiet,LD)$(FUZZ_LINK) $^ $(FUZZ_JANSSON_LINK) $(FUZZ_SOLVER_LIBS) -o $@
$(FUZZ_BUILD)/fuzz/json_scan_fuzz: $(FUZZ_BUILD)/fuzz/json_scan_fuzz.o $(FUZZ_COMMON_OBJ)
	$(call quiet,LD)$(FUZZ_LINK) $^ $(FUZZ_JANSSON_LINK) -lcrypto -o $@
$(FUZZ_BUILD)/fuzz/request_head_fuzz: $(FUZZ_BUILD)/fuzz/request_head_fuzz.o $(FUZZ_BUILD)/server/request_head.o \
		$(FUZZ_BUILD)/server/server.o
	$(call quiet,LD)$(FUZZ_LINK) $^ $(FUZZ_JANSSON_LINK) -lpthread -o $@
$(FUZZ_BUILD)/fuzz/http_fuzz: $(FUZZ_BUILD)/fuzz/http_fuzz.o $(FUZZ_SERVER_OBJ) $(FUZZ_COMMON_OBJ) $(FUZZ_BUILD)/libporo.a
	$(call quiet,LD)$(FUZZ_LINK) $^ -lmicrohttpd -lsqlite3 $(FUZZ_JANSSON_LINK) -lcrypto -lpthread $(FUZZ_SOLVER_LIBS) -o $@
