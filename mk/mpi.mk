# photosplat-ref-mpi: photosplat-ref on MPI (src/dist; docs/reference-renderer.md).
# ref_main.c compiled again with PS_REF_DIST, linked with src/dist (the only
# code that calls MPI, never in the library). Built only where Open MPI's
# ompi-c is found (scripts/install-deps.sh installs it); without it the other
# programs build as before and the MPI tests say they are skipped.
MPI_FOUND := $(shell pkg-config --exists ompi-c 2>/dev/null && echo yes)
ifeq ($(MPI_FOUND),yes)
MPI_CFLAGS := $(shell pkg-config --cflags ompi-c)
MPI_LIBS := $(shell pkg-config --libs ompi-c)
DIST_C := $(wildcard src/dist/*.c)

# mpi-rules(VARIANT)
define mpi-rules
build/$(1)/obj/dist/%.o: src/dist/%.c
	@mkdir -p $$(@D)
	$$(CC) $$(CSTD) $$(WARN) $$(OPT_$(1)) -Isrc $$(PKG_CFLAGS) $$(MPI_CFLAGS) -MMD -MP -c $$< -o $$@
build/$(1)/obj/app/ref_mpi_main.o: src/app/ref_main.c
	@mkdir -p $$(@D)
	$$(CC) $$(CSTD) $$(WARN) $$(OPT_$(1)) -Isrc $$(PKG_CFLAGS) $$(MPI_CFLAGS) -DPS_REF_DIST -MMD -MP -c $$< -o $$@
build/$(1)/bin/photosplat-ref-mpi: build/$(1)/obj/app/ref_mpi_main.o $$(patsubst src/%.c,build/$(1)/obj/%.o,$$(DIST_C)) $$(LIB_$(1))
	@mkdir -p $$(@D)
	$$(CC) $$(LDOPT_$(1)) $$^ -o $$@ $$(MPI_LIBS) $$(LIBS)
-include build/$(1)/obj/app/ref_mpi_main.d $$(patsubst src/%.c,build/$(1)/obj/%.d,$$(DIST_C))
endef
$(eval $(call mpi-rules,release))
$(eval $(call mpi-rules,asan))

all: bin/photosplat-ref-mpi
build-tests: build/asan/bin/photosplat-ref-mpi
endif
