/* fuzz_nrrd.c - libFuzzer target: hd_volume_parse_nrrd on arbitrary bytes (mk/reliability.mk:
   make fuzz-smoke; seeds from tests/fuzz/make_seeds.c, regressions in regressions/nrrd/). */
#include "hybriddiff.h" /* the implementation: tests/fuzz/hd_impl_fuzz.c */
#include "tests/fuzz/hd_fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    hd_volume_file v;
    hd_fuzz_check(hd_volume_parse_nrrd(data, size, &v, hd_fuzz_logger()), &v);
    return 0;
}
