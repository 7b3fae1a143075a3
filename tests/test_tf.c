/* test_tf.c - the examples' transfer functions (examples/hd_tf.h): presets, the text format,
   resampling. */
#include "hybriddiff.h"
#include "hd_test.h"
#include "../examples/hd_tf.h"

static hdx_tf tf_a, tf_b;

static int tf_parse(const char *text, hdx_tf *tf, char *err, size_t n)
{
    err[0] = 0;
    return hdx_tf_parse(text, strlen(text), "t.tf", tf, err, n);
}

static int tf_near(float a, float b) { return fabsf(a - b) < 1e-5f; }

static void tf_presets(void)
{
    int i;
    const char *help = NULL;
    CHECK(hdx_tf_preset_name(HDX_TF_PRESET_COUNT, NULL) == NULL);
    for (i = 0; i < HDX_TF_PRESET_COUNT; ++i) {
        const char *name = hdx_tf_preset_name(i, &help);
        hd_transfer_function d;
        int k;
        CHECK(name != NULL && help != NULL && help[0]);
        CHECK_MSG(hdx_tf_preset(name, &tf_a), "%s", name);
        CHECK(strcmp(tf_a.name, name) == 0);
        CHECK(tf_a.count == HDX_TF_DEFAULT_ENTRIES && tf_a.domain[1] > tf_a.domain[0]);
        CHECK(tf_a.rgba[3] == 0.0f); /* the lowest value is always transparent */
        for (k = 0; k < tf_a.count * 4; ++k)
            CHECK_MSG(tf_a.rgba[k] >= 0.0f && tf_a.rgba[k] <= 1.0f, "%s[%d]", name, k);
        d = hdx_tf_desc(&tf_a);
        CHECK(d.rgba == tf_a.rgba && d.count == tf_a.count);
        CHECK(tf_a.is_ct == (strncmp(name, "ct-", 3) == 0));
        CHECK(tf_a.data_domain == !tf_a.is_ct);
    }
    CHECK(hdx_tf_preset("ct-skin", &tf_a));
    CHECK(tf_a.domain[0] == -1024.0f && tf_a.domain[1] == 3071.0f);
    /* bone (1000 HU) is opaque, air (-1000) transparent */
    CHECK(tf_a.rgba[4 * (int)((1000.0f + 1024.0f) / 4095.0f * 255.0f) + 3] > 0.9f);
    CHECK(tf_a.rgba[4 * 1 + 3] == 0.0f);
    CHECK(hdx_tf_preset("ct-bone", &tf_a));
    CHECK(tf_a.rgba[4 * (int)((0.0f + 1024.0f) / 4095.0f * 255.0f) + 3] == 0.0f); /* no tissue */
    /* ct-flesh: soft tissue (40 HU) flesh-coloured and dense, bone (1000 HU) hidden */
    CHECK(hdx_tf_preset("ct-flesh", &tf_a));
    {
        const float *t = &tf_a.rgba[4 * (int)((40.0f + 1024.0f) / 4095.0f * 255.0f)];
        CHECK(tf_near(t[0], 0.95f) && tf_near(t[1], 0.50f) && tf_near(t[2], 0.35f) && t[3] > 0.6f);
        CHECK(tf_a.rgba[4 * (int)((1000.0f + 1024.0f) / 4095.0f * 255.0f) + 3] == 0.0f);
    }
    CHECK(!hdx_tf_preset("ct-nothing", &tf_a));
    /* the ramp follows the data's range */
    CHECK(hdx_tf_preset("ramp", &tf_a));
    hdx_tf_set_domain(&tf_a, 10.0f, 210.0f);
    CHECK(tf_a.domain[0] == 10.0f && tf_a.domain[1] == 210.0f);
    CHECK(tf_near(tf_a.points[1].value, 20.0f));
    CHECK(tf_near(tf_a.rgba[4 * 255 + 3], 1.0f));
}

static void tf_parse_format(void)
{
    char err[256];
    const char *text =
        "# a comment\n"
        "\n"
        "domain 0 100   # trailing comment\n"
        "entries 5\r\n"
        "  25 1 0 0 0\n"
        "75 0 0 1 1\n";
    CHECK_MSG(tf_parse(text, &tf_a, err, sizeof err), "%s", err);
    CHECK(tf_a.count == 5 && tf_a.point_count == 2);
    CHECK(tf_a.domain[0] == 0.0f && tf_a.domain[1] == 100.0f);
    /* entries at 0, 25, 50, 75, 100: clamped below and above, linear between */
    CHECK(tf_near(tf_a.rgba[0], 1.0f) && tf_near(tf_a.rgba[3], 0.0f));
    CHECK(tf_near(tf_a.rgba[4], 1.0f) && tf_near(tf_a.rgba[7], 0.0f));
    CHECK(tf_near(tf_a.rgba[8], 0.5f) && tf_near(tf_a.rgba[10], 0.5f) && tf_near(tf_a.rgba[11], 0.5f));
    CHECK(tf_near(tf_a.rgba[12], 0.0f) && tf_near(tf_a.rgba[15], 1.0f));
    CHECK(tf_near(tf_a.rgba[16], 0.0f) && tf_near(tf_a.rgba[19], 1.0f));

    /* no domain: the points' span; a step where two points share a value */
    CHECK_MSG(tf_parse("entries 3\n-1e3 0 0 0 0\n0 0 0 0 0\n0 1 1 1 1\n1000 1 1 1 1\n", &tf_a, err,
                       sizeof err), "%s", err);
    CHECK(tf_a.domain[0] == -1000.0f && tf_a.domain[1] == 1000.0f);
    CHECK(tf_near(tf_a.rgba[3], 0.0f) && tf_near(tf_a.rgba[11], 1.0f));
    CHECK(tf_near(tf_a.rgba[7], 0.0f)); /* at the step itself: the first of the two points */

    /* what hdx_tf_write writes reads back the same */
    {
        FILE *f = tmpfile();
        char buf[4096];
        size_t n;
        CHECK(hdx_tf_preset("ct-tissue", &tf_a));
        CHECK(f != NULL);
        if (f) {
            int k, same = 1;
            hdx_tf_write(f, &tf_a);
            rewind(f);
            n = fread(buf, 1, sizeof buf, f);
            fclose(f);
            CHECK_MSG(hdx_tf_parse(buf, n, "dump", &tf_b, err, sizeof err), "%s", err);
            CHECK(tf_b.count == tf_a.count && tf_b.point_count == tf_a.point_count);
            for (k = 0; k < tf_a.count * 4; ++k) same &= fabsf(tf_a.rgba[k] - tf_b.rgba[k]) < 1e-4f;
            CHECK(same);
        }
    }
}

static void tf_parse_errors(void)
{
    static const char *bad[] = {
        "",                                  /* no points */
        "# only a comment\n",
        "0 0 0 0 0\n",                       /* one point */
        "0 0 0 0\n1 1 1 1 1\n",              /* four numbers */
        "0 0 0 0 0 0\n1 1 1 1 1\n",          /* six numbers */
        "0 0 0 0 x\n1 1 1 1 1\n",
        "0 0 0 0 1.5\n1 1 1 1 1\n",          /* alpha > 1 */
        "0 0 -0.1 0 0\n1 1 1 1 1\n",         /* negative colour */
        "5 0 0 0 0\n1 1 1 1 1\n",            /* decreasing */
        "3 0 0 0 0\n3 1 1 1 1\n",            /* no span, no domain */
        "domain 5 5\n0 0 0 0 0\n1 1 1 1 1\n",
        "domain 1\n0 0 0 0 0\n1 1 1 1 1\n",
        "domain 0 1 2\n0 0 0 0 0\n1 1 1 1 1\n",
        "entries 1\n0 0 0 0 0\n1 1 1 1 1\n",
        "entries 100000\n0 0 0 0 0\n1 1 1 1 1\n",
        "entries 2.5\n0 0 0 0 0\n1 1 1 1 1\n",
        "1e99 0 0 0 0\n2e99 1 1 1 1\n",      /* beyond float */
        "colour red\n",
    };
    char err[256];
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        int ok = tf_parse(bad[i], &tf_a, err, sizeof err);
        CHECK_MSG(!ok, "case %d accepted", (int)i);
        CHECK_MSG(strncmp(err, "t.tf", 4) == 0 && !strchr(err, '\n'), "case %d: '%s'", (int)i, err);
    }
    CHECK(!hdx_tf_load("/nonexistent/x.tf", &tf_a, err, sizeof err));
    CHECK(strstr(err, "/nonexistent/x.tf") != NULL);
}

const hd_test_case hd_tests_tf[] = {
    {"tf_presets", tf_presets},
    {"tf_parse_format", tf_parse_format},
    {"tf_parse_errors", tf_parse_errors},
};
const int hd_tests_tf_count = sizeof(hd_tests_tf) / sizeof(hd_tests_tf[0]);
