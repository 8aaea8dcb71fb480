# photosplat: build, test and run.
#
#   make run    install missing Debian packages, build, run the preview on the default scene
#   make test   install missing Debian packages, build, run every test (plain and ASan+UBSan)
#   make        build bin/ only (expects the packages to be there)
#
# Layout: every .c/.cpp under src/ except src/app/*_main.c goes into one static
# library, libphotosplat.a (the GL-free core); each src/app/NAME_main.c is a thin
# program bin/photosplat-NAME. Tests are tests/test_*.c, one per module.
# Two build variants share the sources: build/release (what bin/ holds) and
# build/asan (AddressSanitizer + UndefinedBehaviorSanitizer, tests only).

.DEFAULT_GOAL := all
SHELL := /bin/bash
JOBS ?= $(shell nproc 2>/dev/null || echo 2)

CC := gcc
CXX := g++
CSTD := -std=c11 -D_POSIX_C_SOURCE=200809L
WARN := -Wall -Wextra -Wshadow -Wstrict-prototypes -Wmissing-prototypes -Wpointer-arith -Wvla -Wformat=2
CXXWARN := -Wall -Wextra -Wshadow
# Package flags are read when this Makefile is parsed; the `test` and `run`
# targets install the packages first and then re-enter make, so they are there.
PKGS := libpng libjpeg tinyobjloader OpenEXR
PKG_CFLAGS := $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
PKG_LIBS := $(shell pkg-config --libs $(PKGS) 2>/dev/null)
TEST_CFLAGS := $(shell pkg-config --cflags cmocka 2>/dev/null)
TEST_LIBS := $(shell pkg-config --libs cmocka 2>/dev/null)
LIBS := $(PKG_LIBS) -lstdc++ -lm -lpthread

OPT_release := -O2 -g
OPT_asan := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
LDOPT_release :=
LDOPT_asan := -fsanitize=address,undefined

# src/gl/ is the second library, libpsgl.a: plain gl* drawing code with no
# context of its own. A program links it with exactly one GL implementation:
# photosplat-snap with OSMesa, the window with libGL (never both: platform
# notes). GL_PROGS lists the OSMesa programs, GL tests are tests/test_gl*.c.
LIB_C := $(filter-out src/app/%_main.c src/gl/% src/dist/%,$(wildcard src/*/*.c))
LIB_CXX := $(wildcard src/*/*.cpp)
# src/gl/platform_*.c are the context backends (platform.h): each program
# links one, platform_osmesa with OSMesa, platform_glfw with GLFW and libGL.
GL_C := $(filter-out src/gl/platform_%.c,$(wildcard src/gl/*.c))
MAINS := $(wildcard src/app/*_main.c)
# window_main.c is the preview window, bin/photosplat; every other NAME_main.c
# is bin/photosplat-NAME.
PROGS := $(patsubst src/app/%_main.c,photosplat-%,$(filter-out src/app/window_main.c,$(MAINS))) photosplat
GL_PROGS := photosplat-snap photosplat
TESTS := $(patsubst tests/%.c,%,$(wildcard tests/test_*.c))
# Small programs the command-line tests use (tests/tool_*.c), not tests themselves.
TOOLS := $(patsubst tests/%.c,%,$(wildcard tests/tool_*.c))
GL_TESTS := $(patsubst tests/%.c,%,$(wildcard tests/test_gl*.c))
OSMESA_CFLAGS := $(shell pkg-config --cflags osmesa 2>/dev/null) -DGL_GLEXT_PROTOTYPES
OSMESA_LIBS := $(shell pkg-config --libs osmesa 2>/dev/null)
# The window: GLFW with libGL, never OSMesa in the same program (platform notes).
WINDOW_CFLAGS := $(shell pkg-config --cflags glfw3 gl 2>/dev/null) -DGL_GLEXT_PROTOTYPES
WINDOW_LIBS := $(shell pkg-config --libs glfw3 gl 2>/dev/null)

# variant-rules(VARIANT): objects, library, programs and tests of one variant.
define variant-rules
B_$(1) := build/$(1)
OBJ_$(1) := $$(patsubst src/%.c,build/$(1)/obj/%.o,$$(LIB_C)) $$(patsubst src/%.cpp,build/$(1)/obj/%.o,$$(LIB_CXX))
LIB_$(1) := build/$(1)/libphotosplat.a
GLOBJ_$(1) := $$(patsubst src/%.c,build/$(1)/obj/%.o,$$(GL_C))
GLLIB_$(1) := build/$(1)/libpsgl.a
build/$(1)/obj/%.o: src/%.c
	@mkdir -p $$(@D)
	$$(CC) $$(CSTD) $$(WARN) $$(OPT_$(1)) -Isrc $$(PKG_CFLAGS) -MMD -MP -c $$< -o $$@
build/$(1)/obj/%.o: src/%.cpp
	@mkdir -p $$(@D)
	$$(CXX) -std=c++11 $$(CXXWARN) $$(OPT_$(1)) -Isrc $$(PKG_CFLAGS) -MMD -MP -c $$< -o $$@
$$(LIB_$(1)): $$(OBJ_$(1))
	@rm -f $$@
	ar rcs $$@ $$^
$$(GLLIB_$(1)): $$(GLOBJ_$(1))
	@rm -f $$@
	ar rcs $$@ $$^
build/$(1)/obj/gl/%.o: src/gl/%.c
	@mkdir -p $$(@D)
	$$(CC) $$(CSTD) $$(WARN) $$(OPT_$(1)) -Isrc $$(OSMESA_CFLAGS) -MMD -MP -c $$< -o $$@
build/$(1)/bin/photosplat-snap: build/$(1)/obj/app/snap_main.o build/$(1)/obj/gl/platform_osmesa.o $$(GLLIB_$(1)) $$(LIB_$(1))
	@mkdir -p $$(@D)
	$$(CC) $$(LDOPT_$(1)) $$^ -o $$@ $$(OSMESA_LIBS) $$(LIBS)
build/$(1)/bin/photosplat: build/$(1)/obj/app/window_main.o build/$(1)/obj/gl/platform_glfw.o $$(GLLIB_$(1)) $$(LIB_$(1))
	@mkdir -p $$(@D)
	$$(CC) $$(LDOPT_$(1)) $$^ -o $$@ $$(WINDOW_LIBS) $$(LIBS)
build/$(1)/obj/gl/platform_glfw.o: src/gl/platform_glfw.c
	@mkdir -p $$(@D)
	$$(CC) $$(CSTD) $$(WARN) $$(OPT_$(1)) -Isrc $$(PKG_CFLAGS) $$(WINDOW_CFLAGS) -MMD -MP -c $$< -o $$@
build/$(1)/obj/app/window_main.o: src/app/window_main.c
	@mkdir -p $$(@D)
	$$(CC) $$(CSTD) $$(WARN) $$(OPT_$(1)) -Isrc $$(PKG_CFLAGS) $$(WINDOW_CFLAGS) -MMD -MP -c $$< -o $$@
build/$(1)/obj/app/snap_main.o: src/app/snap_main.c
	@mkdir -p $$(@D)
	$$(CC) $$(CSTD) $$(WARN) $$(OPT_$(1)) -Isrc $$(PKG_CFLAGS) $$(OSMESA_CFLAGS) -MMD -MP -c $$< -o $$@
$$(patsubst %,build/$(1)/tests/%,$$(GL_TESTS)): build/$(1)/tests/%: tests/%.c $$(GLLIB_$(1)) $$(LIB_$(1))
	@mkdir -p $$(@D)
	$$(CC) $$(CSTD) $$(WARN) $$(OPT_$(1)) -Isrc -Itests $$(TEST_CFLAGS) $$(OSMESA_CFLAGS) -MMD -MP $$< -o $$@ $$(LDOPT_$(1)) $$(filter %.o,$$^) $$(GLLIB_$(1)) $$(LIB_$(1)) $$(TEST_LIBS) $$(OSMESA_LIBS) $$(LIBS)
# The GL test of snap's context backend links it (the others make their own).
build/$(1)/tests/test_gl_platform: build/$(1)/obj/gl/platform_osmesa.o
build/$(1)/bin/photosplat-%: build/$(1)/obj/app/%_main.o $$(LIB_$(1))
	@mkdir -p $$(@D)
	$$(CC) $$(LDOPT_$(1)) $$^ -o $$@ $$(LIBS)
build/$(1)/tests/%: tests/%.c $$(LIB_$(1))
	@mkdir -p $$(@D)
	$$(CC) $$(CSTD) $$(WARN) $$(OPT_$(1)) -Isrc -Itests $$(TEST_CFLAGS) -MMD -MP $$< -o $$@ $$(LDOPT_$(1)) $$(LIB_$(1)) $$(TEST_LIBS) $$(LIBS)
-include $$(OBJ_$(1):.o=.d) $$(GLOBJ_$(1):.o=.d) build/$(1)/obj/gl/platform_osmesa.d build/$(1)/obj/gl/platform_glfw.d $$(patsubst src/%.c,build/$(1)/obj/%.d,$$(MAINS)) $$(patsubst %,build/$(1)/tests/%.d,$$(TESTS))
endef
$(eval $(call variant-rules,release))
$(eval $(call variant-rules,asan))
# Programs' objects are not in the library; keep them when make would call them intermediate.
.SECONDARY:

# Copied then renamed: a running bin/ program (a benchmark, a window) keeps
# its old file instead of failing the copy with "text file busy".
bin/%: build/release/bin/%
	@mkdir -p bin
	cp $< $@.tmp.$$$$ && mv -f $@.tmp.$$$$ $@

.PHONY: all deps test check run run-built bench clean build-tests
all: $(addprefix bin/,$(PROGS))

build-tests: all $(addprefix build/release/tests/,$(TESTS) $(TOOLS)) \
             $(addprefix build/asan/tests/,$(TESTS) $(TOOLS)) $(addprefix build/asan/bin/,$(PROGS))

deps:
	@scripts/install-deps.sh

# The public entry points install packages, then re-enter make so that the
# pkg-config flags above are read with the packages present.
test: deps
	@$(MAKE) --no-print-directory -j$(JOBS) build-tests
	@$(MAKE) --no-print-directory check

check:
	@tests/run-tests.sh

run: deps
	@$(MAKE) --no-print-directory -j$(JOBS) all
	@$(MAKE) --no-print-directory run-built

# Benchmarks: every bench/bench_NAME.c becomes build/release/bench/bench_NAME
# (release flags, linked against the release library); `make bench` installs
# packages, builds them and runs each in turn (scripts/bench.sh).
# Embree 3 is a bench-only baseline, never linked by the library or tests:
# found through pkg-config (embree3) or, since Debian's libembree-dev ships no
# .pc file, through its header (then -lembree3). Recursive (=) so that the
# probe runs only when a bench program is built.
BENCHES := $(patsubst bench/%.c,build/release/bench/%,$(wildcard bench/bench_*.c))
EMBREE_HOW = $(shell if pkg-config --exists embree3 2>/dev/null; then echo pc; \
                     elif $(CC) -E -include embree3/rtcore.h -x c /dev/null >/dev/null 2>&1; then echo header; fi)
EMBREE_CFLAGS = $(if $(filter pc,$(EMBREE_HOW)),-DPS_HAVE_EMBREE $(shell pkg-config --cflags embree3),$(if $(filter header,$(EMBREE_HOW)),-DPS_HAVE_EMBREE))
EMBREE_LIBS = $(if $(filter pc,$(EMBREE_HOW)),$(shell pkg-config --libs embree3),$(if $(filter header,$(EMBREE_HOW)),-lembree3))
build/release/bench/%: bench/%.c $(LIB_release)
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(WARN) -O2 -g -Isrc -Ibench $(EMBREE_CFLAGS) -MMD -MP $< -o $@ $(LIB_release) $(EMBREE_LIBS) $(LIBS)
# GL benches (bench/bench_gl*.c) draw with OSMesa and the GL library.
GL_BENCHES := $(patsubst bench/%.c,build/release/bench/%,$(wildcard bench/bench_gl*.c))
$(GL_BENCHES): build/release/bench/%: bench/%.c $(GLLIB_release) $(LIB_release)
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(WARN) -O2 -g -Isrc -Ibench $(OSMESA_CFLAGS) -MMD -MP $< -o $@ $(GLLIB_release) $(LIB_release) $(OSMESA_LIBS) $(LIBS)
-include $(BENCHES:=.d)

.PHONY: build-bench
build-bench: $(BENCHES)

bench:
	@scripts/install-deps.sh --bench
	@$(MAKE) --no-print-directory -j$(JOBS) all build-bench
	@scripts/bench.sh

SCENE ?= data/scenes/cornell-caustic.scn
# The default scene's walls reflect radiance of about 1-3 W sr^-1 m^-2; this
# exposure maps them into the PNG's range.
EXPOSURE ?= 0.3
RUN_PNG ?= out/default.png
# The window when there is a display; else the same preview headless
# (photosplat-snap, 2 s of refinement) to a PNG, and where it went.
run-built:
	@if [ -n "$${DISPLAY:-}" ] && bin/photosplat $(SCENE) --exposure $(EXPOSURE); then :; else \
	    mkdir -p $(dir $(RUN_PNG)) && \
	    bin/photosplat-snap $(SCENE) -o $(RUN_PNG) --exposure $(EXPOSURE) --time 2 \
	        --caustic-photons 2000000 --global-photons 400000 && \
	    echo "make run: no display: the default scene, previewed headless for 2 s, is in $(RUN_PNG)"; fi

# Screenshots of the window for the README, under Xvfb.
.PHONY: screenshots
screenshots: deps
	@$(MAKE) --no-print-directory -j$(JOBS) all
	@scripts/screenshots.sh

clean:
	rm -rf build bin

# Further targets, one concern a file (fuzzing, stress, soak, valgrind): they
# use the variables and rules above.
-include $(sort $(wildcard mk/*.mk))
