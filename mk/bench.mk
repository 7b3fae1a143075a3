# mk/bench.mk - the interactive-use benchmarks (none of them is part of `make test`):
#   make bench-peer     hybriddiff's projection frame over converged light (CPU backend) against
#                       VTK's fixed-point CPU ray caster, its GPU ray caster (Mesa llvmpipe) and
#                       its volumetric-scattering mode, head CT, 512^2 and 1024^2, interleaved in
#                       one run (bench/peer/); pictures -> docs/peer/. Needs ParaView's pvpython
#                       (Debian python3-paraview) and xvfb-run (xvfb): installed by apt-get here,
#                       on demand, when missing (root). Knobs: PEER_ARGS (see vtk_peer.py),
#                       HDPEER_LIGHT_ITERS (light iteration cap, default 64).
#   make bench-orbit    bench/hdbench_orbit.c: converge HD's light once, then an orbit of K views:
#                       ms per orbit frame on every backend (CPU, OpenCL, Vulkan, GL) at
#                       render_scale 1, 2 and 4, and on the CPU backend HD's (render_scale auto)
#                       and PT_MS's PSNR per per-view time budget against PT_MS references ->
#                       docs/orbit/ (CSV, gnuplot PNG), the crossover budget. The library's
#                       default hd_params; ORBIT_ARGS="--preset paper" for the paper's.
#                       Default ~10 min on 2 cores (256^2 PSNR part, references cached in
#                       build/orbit-cache); ORBIT_ARGS for the full run, e.g.
#                       ORBIT_ARGS="--size 512 --ref-iters 1024 --views 16".
#                       ORBIT_BACKENDS picks the frame-time builds (default opencl vulkan gl).
.PHONY: bench-peer bench-orbit

PEER_SRC := bench/peer/hdpeer.c bench/hd_orbit_scene.h examples/hd_tf.h examples/hd_tonemap.h examples/hd_png.h
$(B)/hdpeer: $(PEER_SRC) $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) -Iexamples -Ibench $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)
# The GPU backends' builds and the CPU build of PROJECT_BASE (mk/bench_project.mk), for
# PEER_ARGS="--hd cpu=build/hdpeer --hd gl=build/hdpeer_gl ..." (bench/peer/vtk_peer.py).
$(B)/hdpeer_opencl: $(PEER_SRC) $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) -Iexamples -Ibench -DHYBRIDDIFF_BACKEND_OPENCL $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) -lOpenCL
$(B)/hdpeer_gl: $(PEER_SRC) $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) -Iexamples -Ibench -DHYBRIDDIFF_BACKEND_GL $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) -lEGL
$(B)/hdpeer_vulkan: $(PEER_SRC) $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) -Iexamples -Ibench -DHYBRIDDIFF_BACKEND_VULKAN $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) -lvulkan
$(B)/hdpeer_old: $(PEER_SRC) $(B)/proj-old/.stamp
	$(CC) -I$(PROJECT_OLD) -D_POSIX_C_SOURCE=200809L -Iexamples -Ibench $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)
# the same for a GPU backend of PROJECT_BASE: build/hdpeer_old_{opencl,gl,vulkan}
$(B)/hdpeer_old_%: $(PEER_SRC) $(B)/proj-old/.stamp
	$(CC) -I$(PROJECT_OLD) -D_POSIX_C_SOURCE=200809L -Iexamples -Ibench $(PROJECT_DEF_$*) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(PROJECT_LIB_$*)

PEER_ARGS ?=
bench-peer: $(B)/hdpeer
	@test -f data/head.nrrd || scripts/fetch-data
	@command -v pvpython >/dev/null && command -v xvfb-run >/dev/null || \
	    { echo "bench-peer: installing python3-paraview and xvfb (apt-get)"; \
	      DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends python3-paraview xvfb xauth; }
	xvfb-run -a -s "-screen 0 1280x1280x24" pvpython bench/peer/vtk_peer.py --hdpeer $(B)/hdpeer $(PEER_ARGS)

ORBIT_SRC := bench/hdbench_orbit.c bench/hd_orbit_scene.h examples/hd_tf.h examples/hd_tonemap.h $(LIB_SRC)
ORBIT_CC = $(CC) $(CPPFLAGS) -Iexamples -Ibench $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)
$(B)/hdbench_orbit: $(ORBIT_SRC) | $(B)
	$(ORBIT_CC) -DHYBRIDDIFF_BACKEND_CPU
$(B)/hdbench_orbit_opencl: $(ORBIT_SRC) | $(B)
	$(ORBIT_CC) -DHYBRIDDIFF_BACKEND_OPENCL -lOpenCL
$(B)/hdbench_orbit_vulkan: $(ORBIT_SRC) | $(B)
	$(ORBIT_CC) -DHYBRIDDIFF_BACKEND_VULKAN -lvulkan
$(B)/hdbench_orbit_gl: $(ORBIT_SRC) | $(B)
	$(ORBIT_CC) -DHYBRIDDIFF_BACKEND_GL -lEGL

ORBIT_ARGS ?=
ORBIT_BACKENDS ?= opencl vulkan gl
bench-orbit: $(B)/hdbench_orbit $(patsubst %,$(B)/hdbench_orbit_%,$(ORBIT_BACKENDS))
	@test -f data/head.nrrd || scripts/fetch-data
	$(B)/hdbench_orbit $(ORBIT_ARGS)
	@for b in $(ORBIT_BACKENDS); do echo "== $$b"; $(B)/hdbench_orbit_$$b --no-psnr $(ORBIT_ARGS) || exit 1; done

# make bench-animated: bench/hdbench_animated.c on the CPU backend: a procedural smoke puff at
# 64^3 and 128^3 (300 frames, camera orbiting, 512^2) under render_budget 2, 4, 8, 16 and 50 ms:
# hd_update_volume per frame (p50 / p99, frames over the budget) against destroy + create, and
# the lag (PSNR against each frame's converged light); then the TF slider on the head CT, warm
# against cold (hd_reset). Per-frame rows go to $(B)/animated.csv; scripts/plot-animated draws
# docs/animated/*.png from it (gnuplot). ANIMATED_ARGS are added to each run (e.g.
# --frames 60); ANIMATED_BACKENDS="gl vulkan" runs the puffs on those backends too.
.PHONY: bench-animated
ANIMATED_CC = $(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)
$(B)/hdbench_animated: bench/hdbench_animated.c $(LIB_SRC) | $(B)
	$(ANIMATED_CC)
$(B)/hdbench_animated_opencl: bench/hdbench_animated.c $(LIB_SRC) | $(B)
	$(ANIMATED_CC) -DHYBRIDDIFF_BACKEND_OPENCL -lOpenCL
$(B)/hdbench_animated_vulkan: bench/hdbench_animated.c $(LIB_SRC) | $(B)
	$(ANIMATED_CC) -DHYBRIDDIFF_BACKEND_VULKAN -lvulkan
$(B)/hdbench_animated_gl: bench/hdbench_animated.c $(LIB_SRC) | $(B)
	$(ANIMATED_CC) -DHYBRIDDIFF_BACKEND_GL -lEGL
ANIMATED_ARGS ?=
ANIMATED_BACKENDS ?=
ANIMATED_BUDGETS ?= 2,4,8,16,50
bench-animated: $(B)/hdbench_animated $(patsubst %,$(B)/hdbench_animated_%,$(ANIMATED_BACKENDS))
	@test -f data/head.nrrd || scripts/fetch-data
	rm -f $(B)/animated.csv
	@for b in cpu $(ANIMATED_BACKENDS); do \
	    x=$(B)/hdbench_animated; [ $$b = cpu ] || x=$(B)/hdbench_animated_$$b; \
	    for s in 64 128; do $$x --dims $$s --no-tf --budget $(ANIMATED_BUDGETS) --csv $(B)/animated.csv $(ANIMATED_ARGS) || exit 1; done; \
	done
	$(B)/hdbench_animated --no-puff --csv $(B)/animated.csv $(ANIMATED_ARGS)

# bench/hdbench_guard.c: the per-context in-call guard's cost, the library built with it and
# without it (HD__NO_CALL_GUARD) in one program: ns per hd_get_stats and per hd_render
# (docs/PERFORMANCE.md, "The in-call guard").
.PHONY: bench-guard
$(B)/hdbench_guard_on.o: bench/hdbench_guard.c $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -DHB_SIDE=hb_on -c $< -o $@
$(B)/hdbench_guard_off.o: bench/hdbench_guard.c $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -DHB_SIDE=hb_off -DHD__NO_CALL_GUARD -c $< -o $@
$(B)/hdbench_guard: bench/hdbench_guard.c $(B)/hdbench_guard_on.o $(B)/hdbench_guard_off.o
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< $(B)/hdbench_guard_on.o $(B)/hdbench_guard_off.o -o $@ $(LDLIBS)
bench-guard: $(B)/hdbench_guard
	$(B)/hdbench_guard

# make eval-refine: bench/hdbench_refine.c on the CPU backend: PSNR against a PT_MS reference
# per time budget for HD, PT_MS and HD with params.rest = HD_REST_REFINE (several
# refine_bounces) on one view of the head CT at 128^2, ct-skin and ct-bone, HD from scratch and
# with converged light (docs/DESIGN-REFINE.md). The references are cached in build/refine-cache.
# REFINE_ARGS are added to each run.
.PHONY: eval-refine
REFINE_ARGS ?=
$(B)/hdbench_refine: bench/hdbench_refine.c bench/hd_orbit_scene.h examples/hd_tf.h examples/hd_tonemap.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) -Iexamples -Ibench $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) -DHYBRIDDIFF_BACKEND_CPU
eval-refine: $(B)/hdbench_refine
	@test -f data/head.nrrd || scripts/fetch-data
	@for tf in ct-skin ct-bone; do for w in "" --warm; do \
	    $(B)/hdbench_refine --tf $$tf $$w --csv $(B)/refine-$$tf$$w.csv $(REFINE_ARGS) || exit 1; done; done
# make eval-refine-256: HD, PT_MS, REFINE and BLEND at 256^2 (scripts/eval-refine-256, about 15
# min of CPU; docs/DESIGN-REFINE.md).
.PHONY: eval-refine-256
eval-refine-256: $(B)/hdbench_refine
	scripts/eval-refine-256

# make bench-budget: bench/hdbench_budget.c on every backend: the head CT orbit (200 frames,
# HD_RENDER_SCALE_AUTO, the light cold at the start) at 1280x720 and 1920x1080 under rising
# render_budgets: hd_render's p50 / p99 / max and the frames over each budget, and the smallest
# budget with none over (docs/PERFORMANCE.md, "A budget that holds"). BUDGET_ARGS are added to
# each run; BUDGET_BACKENDS picks the GPU backends.
.PHONY: bench-budget
BUDGET_SRC := bench/hdbench_budget.c bench/hd_orbit_scene.h examples/hd_tf.h examples/hd_tonemap.h $(LIB_SRC)
BUDGET_CC = $(CC) $(CPPFLAGS) -Iexamples -Ibench $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)
$(B)/hdbench_budget: $(BUDGET_SRC) | $(B)
	$(BUDGET_CC) -DHYBRIDDIFF_BACKEND_CPU
$(B)/hdbench_budget_opencl: $(BUDGET_SRC) | $(B)
	$(BUDGET_CC) -DHYBRIDDIFF_BACKEND_OPENCL -lOpenCL
$(B)/hdbench_budget_vulkan: $(BUDGET_SRC) | $(B)
	$(BUDGET_CC) -DHYBRIDDIFF_BACKEND_VULKAN -lvulkan
$(B)/hdbench_budget_gl: $(BUDGET_SRC) | $(B)
	$(BUDGET_CC) -DHYBRIDDIFF_BACKEND_GL -lEGL
BUDGET_ARGS ?=
BUDGET_BACKENDS ?= opencl vulkan gl
bench-budget: $(B)/hdbench_budget $(patsubst %,$(B)/hdbench_budget_%,$(BUDGET_BACKENDS))
	@test -f data/head.nrrd || scripts/fetch-data
	$(B)/hdbench_budget $(BUDGET_ARGS)
	@for b in $(BUDGET_BACKENDS); do echo "== $$b"; $(B)/hdbench_budget_$$b $(BUDGET_ARGS) || exit 1; done
