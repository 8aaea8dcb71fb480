# make valgrind: the GL-free programs and unit tests of the release build
# under valgrind memcheck (scripts/valgrind.sh says which, and why some are
# left out); a few minutes, so not part of `make test`.
VALGRIND_TESTS := $(addprefix build/release/tests/,$(filter-out test_gl%,$(TESTS)))
VALGRIND_PROGS := $(addprefix build/release/bin/,photosplat-info photosplat-ref photosplat-compare)

.PHONY: valgrind valgrind-build valgrind-deps
valgrind: deps valgrind-deps
	@$(MAKE) --no-print-directory -j$(JOBS) valgrind-build
	@scripts/valgrind.sh

valgrind-build: $(VALGRIND_PROGS) $(VALGRIND_TESTS)

# valgrind is a Debian package like the others; installed when missing.
valgrind-deps:
	@command -v valgrind >/dev/null 2>&1 || { \
	    S=$$([ "$$(id -u)" -eq 0 ] || echo sudo); \
	    DEBIAN_FRONTEND=noninteractive $$S apt-get install -y --no-install-recommends valgrind >/dev/null 2>&1 || \
	    { $$S apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$S apt-get install -y --no-install-recommends valgrind; }; }
