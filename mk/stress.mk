# stress.mk: `make stress`, the part of the numerical stress suite too long
# for `make test` (docs/stress.md): tests/test_stress with ten times the
# photons (PS_STRESS_FACTOR, default 10) and tests/cli_stress.sh with larger
# images and 10^7 photons into an 8-bit buffer (STRESS_LONG=1).
.PHONY: stress build-stress
build-stress: build/release/tests/test_stress $(addprefix build/release/bin/,photosplat-ref photosplat-snap photosplat-compare)

stress: deps
	@$(MAKE) --no-print-directory -j$(JOBS) build-stress
	@scripts/stress.sh
