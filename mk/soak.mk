# make soak: the preview window's long session under Xvfb (minutes; not part
# of make test): flat memory and an unchanged picture after a few hundred
# random light and object moves (scripts/soak.sh; SOAK_SECONDS, SOAK_MOVES,
# SOAK_SEED set its length and moves).
.PHONY: soak
soak: deps
	@$(MAKE) --no-print-directory -j$(JOBS) bin/photosplat bin/photosplat-compare
	@scripts/soak.sh
