# mk/bench_energy.mk - HD's energy balance against PT_MS and PT_SS (bench/hdbench_energy.c; figures
# in docs/EVALUATION.md, "Energy balance").
#   make bench-energy    build/hdbench_energy on the head CT (ct-skin, ct-bone), brainsmall and the
#                        CGAL skull; ENERGY_ARGS adds options (--size, --ref-paths, --cases, ...);
#                        references are cached in build/energy-cache
ENERGY_ARGS ?=

.PHONY: bench-energy

$(B)/hdbench_energy: bench/hdbench_energy.c examples/hd_tf.h examples/hd_png.h examples/hd_tonemap.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

bench-energy: $(B)/hdbench_energy
	@test -f data/head.nrrd -a -f data/brainsmall.nrrd || scripts/fetch-data
	@test -f data/skull.nrrd || scripts/fetch-skull
	nice -n 5 $(B)/hdbench_energy $(ENERGY_ARGS)
