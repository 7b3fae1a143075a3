# mk/multigrid.mk - the multigrid diffusion solver's benchmark.
#   make bench-multigrid   build/hdbench_multigrid on the head CT (make data): time to a relative
#                          residual of 1e-4, red-black sweeps against HD_SOLVER_MULTIGRID's steps
#                          (conjugate gradients preconditioned by a V-cycle)
#                          (BENCH_ARGS="--f64 --surface-only" evaluates the residual in double,
#                          --downsample 2 at half resolution)
.PHONY: bench-multigrid
$(B)/hdbench_multigrid: bench/hdbench_multigrid.c bench/hd_residual_f64.c bench/hd_residual_f64.h examples/hd_tf.h $(LIB_SRC) src/hd_test_hooks.h | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -Ibench bench/hdbench_multigrid.c bench/hd_residual_f64.c -o $@ $(LDLIBS)

bench-multigrid: $(B)/hdbench_multigrid data
	$(B)/hdbench_multigrid $(BENCH_ARGS)
