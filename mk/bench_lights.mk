# mk/bench_lights.mk - area lights on the head CT (bench/hdbench_lights.c, figures in
# docs/DESIGN-LIGHTS.md): HD's iteration cost with a quad and a sphere light against one
# directional light, HD's PSNR against PT_MS for the directional light and the quad, and the
# light choice by estimate against the uniform one with a strong and a weak light.
#   make bench-lights  build/hdbench_lights on the head CT; LIGHTS_ARGS (--size, --paths,
#                      --rounds, --samples)
LIGHTS_ARGS ?= --size 128 --paths 1024 --rounds 8 --samples 32

.PHONY: bench-lights

$(B)/hdbench_lights: bench/hdbench_lights.c bench/hd_bench_median.h examples/hd_tf.h examples/hd_crop.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

bench-lights: $(B)/hdbench_lights data
	$(B)/hdbench_lights $(LIGHTS_ARGS) data/head.nrrd
