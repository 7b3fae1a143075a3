/* fuzz_mhd.c - libFuzzer target: hd_volume_parse_mhd; the input is both the header and the
   detached data file's bytes (so LOCAL and detached paths both run). */
#include "hybriddiff.h" /* the implementation: tests/fuzz/hd_impl_fuzz.c */
#include "tests/fuzz/hd_fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    hd_volume_file v;
    hd_fuzz_check(hd_volume_parse_mhd(data, size, data, size, &v, hd_fuzz_logger()), &v);
    return 0;
}
