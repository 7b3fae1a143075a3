/* hd_bench_median.h - the median the benchmarks report (sorts v in place); header-only. */
#ifndef HD_BENCH_MEDIAN_H
#define HD_BENCH_MEDIAN_H
#include <stdlib.h>

static int hdb_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

#if defined(__GNUC__) || defined(__clang__)
__attribute__((unused))
#endif
static double hdb_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, hdb_cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
#endif
