# mk/hdeval.mk - examples/hdeval, the evaluation harness (Table 1, Figures 2-7, the paper's claims).
#   make build/hdeval   build it
#   make eval           the reduced evaluation (examples/eval/head.scene, 256^2; ~15 min on 2 cores)
#                       -> docs/eval/*; reference images are cached in out/eval-cache
#   make eval-paper     the paper-scale settings (--paper: 1024^2, 1.3M-path references) -> out/eval-paper
#   make eval-multigrid the multigrid study: HD's PSNR against PT_MS over time, red-black and
#                       multigrid CG (head-tissue, 128^2, illumination grid /2; ~6 min on 2 cores)
#                       -> docs/eval/multigrid/
#   make eval-defaults  the library's defaults against the paper's settings (hdeval --defaults-study)
#                       on the head CT and brainsmall -> docs/eval/defaults/ (~10 min on 2 cores)
#   make build/hdslab   a homogeneous slab against PT_MS (examples/hdslab.c: why HD is too dark)
.PHONY: eval eval-paper eval-multigrid eval-defaults

$(B)/hdeval: examples/hdeval.c $(wildcard examples/*.h) $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

$(B)/hdslab: examples/hdslab.c $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

eval: $(B)/hdeval
	@test -f data/head.nrrd || scripts/fetch-data
	$(B)/hdeval examples/eval/head.scene --out docs/eval --cache out/eval-cache

eval-paper: $(B)/hdeval
	@test -f data/head.nrrd || scripts/fetch-data
	$(B)/hdeval examples/eval/head.scene --paper --out out/eval-paper --cache out/eval-cache

eval-multigrid: $(B)/hdeval
	@test -f data/head.nrrd || scripts/fetch-data
	$(B)/hdeval examples/eval/head-tissue.scene --multigrid-study --size 128 --downsample 2 --study-seconds 20 \
	    --out docs/eval/multigrid --cache out/eval-cache --work out/eval-work-mg

eval-defaults: $(B)/hdeval
	@test -f data/head.nrrd -a -f data/brainsmall.nrrd || scripts/fetch-data
	$(B)/hdeval examples/eval/head.scene --defaults-study --out out/eval-defaults/head --cache out/eval-cache
	$(B)/hdeval examples/eval/brainsmall.scene --defaults-study --out out/eval-defaults/brainsmall --cache out/eval-cache
	mkdir -p docs/eval/defaults
	for v in head brainsmall; do cp out/eval-defaults/$$v/defaults.md docs/eval/defaults/$$v.md; \
	    cp out/eval-defaults/$$v/defaults.csv docs/eval/defaults/$$v.csv; \
	    cp out/eval-defaults/$$v/defaults-checks.txt docs/eval/defaults/$$v-checks.txt; done
