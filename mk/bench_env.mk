# mk/bench_env.mk - the environment light on the head CT (bench/hdbench_env.c, figures in
# docs/PERFORMANCE.md and docs/EVALUATION.md): HD's iteration cost with the map against one
# directional light, method_bytes, and HD's PSNR against PT_MS for both.
#   make bench-env     build/hdbench_env on the head CT with the map of scripts/make-env
#                      (256x128); ENV_ARGS (--size, --paths, --rounds, --intensity)
ENV_ARGS ?= --size 128 --paths 1024 --rounds 8

.PHONY: bench-env

$(B)/hdbench_env: bench/hdbench_env.c bench/hd_bench_median.h examples/hd_tf.h examples/hd_env.h examples/hd_crop.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

$(B)/sky.hdr: scripts/make-env | $(B)
	scripts/make-env $@

bench-env: $(B)/hdbench_env $(B)/sky.hdr data
	$(B)/hdbench_env $(ENV_ARGS) $(B)/sky.hdr data/head.nrrd
