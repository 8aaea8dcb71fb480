# fuzz.mk: libFuzzer targets (fuzz/fuzz_*.c) and `make fuzz` (docs/fuzzing.md).
#
# The core library is compiled a third time, by clang, into build/fuzz/ with
# -fsanitize=fuzzer-no-link so libFuzzer sees its edges; only the targets link
# the fuzzer runtime. clang is needed for this only: `make test` builds the
# replay test (tests/test_fuzz_replay.c, the same target bodies) with gcc.

FUZZ_CC ?= clang
FUZZ_CXX ?= clang++
FUZZ_SAN := -fsanitize=address,undefined -fno-sanitize-recover=undefined
FUZZ_OPT := -O1 -g -fno-omit-frame-pointer
FUZZ_OBJ := $(patsubst src/%.c,build/fuzz/obj/%.o,$(LIB_C)) $(patsubst src/%.cpp,build/fuzz/obj/%.o,$(LIB_CXX))
FUZZ_LIB := build/fuzz/libphotosplat.a
FUZZ_TARGETS := $(patsubst fuzz/%.c,build/fuzz/bin/%,$(wildcard fuzz/fuzz_*.c))

build/fuzz/obj/%.o: src/%.c
	@mkdir -p $(@D)
	$(FUZZ_CC) $(CSTD) $(WARN) $(FUZZ_OPT) $(FUZZ_SAN) -fsanitize=fuzzer-no-link -Isrc $(PKG_CFLAGS) \
	    -MMD -MP -c $< -o $@
build/fuzz/obj/%.o: src/%.cpp
	@mkdir -p $(@D)
	$(FUZZ_CXX) -std=c++11 $(CXXWARN) $(FUZZ_OPT) $(FUZZ_SAN) -fsanitize=fuzzer-no-link -Isrc $(PKG_CFLAGS) -MMD -MP -c $< -o $@
$(FUZZ_LIB): $(FUZZ_OBJ)
	@rm -f $@
	ar rcs $@ $^
# The harness sources (fuzz/*.c) get their own object folder, so no pattern
# rule above can claim them.
build/fuzz/harness/%.o: fuzz/%.c
	@mkdir -p $(@D)
	$(FUZZ_CC) $(CSTD) $(WARN) $(FUZZ_OPT) $(FUZZ_SAN) -fsanitize=fuzzer-no-link -Isrc $(PKG_CFLAGS) -MMD -MP -c $< -o $@
build/fuzz/bin/fuzz_%: build/fuzz/harness/fuzz_%.o build/fuzz/harness/targets.o $(FUZZ_LIB)
	@mkdir -p $(@D)
	$(FUZZ_CXX) $(FUZZ_SAN) -fsanitize=fuzzer $^ -o $@ $(LIBS)
-include $(FUZZ_OBJ:.o=.d) $(patsubst fuzz/%.c,build/fuzz/harness/%.d,$(wildcard fuzz/*.c))

# The replay test links the target bodies (fuzz/targets.c) into a cmocka
# program, in both variants; this explicit rule takes precedence over the
# Makefile's tests/%.c pattern rule.
define fuzz-replay-rule
build/$(1)/tests/test_fuzz_replay: tests/test_fuzz_replay.c fuzz/targets.c fuzz/fuzz_targets.h tests/test.h $$(LIB_$(1))
	@mkdir -p $$(@D)
	$$(CC) $$(CSTD) $$(WARN) $$(OPT_$(1)) -Isrc -Itests -Ifuzz $$(PKG_CFLAGS) $$(TEST_CFLAGS) \
	    tests/test_fuzz_replay.c fuzz/targets.c -o $$@ $$(LDOPT_$(1)) $$(LIB_$(1)) $$(TEST_LIBS) $$(LIBS)
endef
$(foreach v,release asan,$(eval $(call fuzz-replay-rule,$(v))))

.PHONY: fuzz build-fuzz
build-fuzz: $(FUZZ_TARGETS)

# FUZZ_SECONDS per target (default 60); FUZZ_TARGETS_RUN picks some ("scene png").
fuzz:
	@scripts/fuzz.sh
