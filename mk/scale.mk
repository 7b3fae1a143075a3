# mk/scale.mk - how light and memory scale with the volume (not part of `make test`).
#   make bench-scale   build/hdbench_scale (bench/hdbench_scale.c, CPU backend): the head CT
#                      (make data) resampled to SCALE_SIZES and a procedural sparse cloud at
#                      SCALE_CLOUDS, per solver of SCALE_SOLVERS (rb, mg, auto: the default's
#                      pick): device bytes per voxel, host peak in hd_create, light iteration,
#                      iterations, wall and CPU seconds to converge, a 512^2 frame; the table on stdout, gnuplot's data in build/scale.dat and, where
#                      gnuplot is installed, the log-log plot docs/scale.png (scripts/plot-scale).
SCALE_SIZES ?= 256,512
SCALE_CLOUDS ?= 256,512
SCALE_SOLVERS ?= rb,mg
SCALE_ARGS ?=
.PHONY: bench-scale
$(B)/hdbench_scale: bench/hdbench_scale.c examples/hd_tf.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

bench-scale: $(B)/hdbench_scale data
	$(B)/hdbench_scale --sizes $(SCALE_SIZES) --cloud $(SCALE_CLOUDS) --solvers $(SCALE_SOLVERS) --dat $(B)/scale.dat $(SCALE_ARGS)
	@if command -v gnuplot >/dev/null; then scripts/plot-scale $(B)/scale.dat docs/scale.png; \
	else echo "bench-scale: no gnuplot (apt-get install gnuplot): no plot"; fi
