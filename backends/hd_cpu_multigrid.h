/* hd_cpu_multigrid.h - the CPU backend's multigrid primitives (src/hd_backend.h's hd__be_mg_*;
   the step that runs them is src/hd_multigrid.h). The per-voxel math is the shared
   backends/kernels/hd_k_multigrid.h. Every level's buffers are in the colour layout, so the
   smoothing runs the sweep's unit-stride rows; the transfers and dot products load each row they
   read once, as its two unit-stride half-rows (hd__cpu_mg_load_row), because a load by
   coordinates alternates between them (docs/DESIGN-MULTIGRID.md has the measurements). */

/* Elements of a level's grid of `channels` channels: every buffer is in the colour layout
   (hd_prelude_c.h's hd__split_slot, as the backend's sigma_t, E and phi), so the shared kernels
   and the sweep's row loop read them alike; padding slots stay 0. */
static size_t hd__mg_slots(const int *d, int channels) { return hd__split_slots(d[0], d[1], (size_t)d[2] * (size_t)channels); }

/* Bytes the solver holds (r, z, p, the fine residual and every coarse grid); 0 without it. */
static const char *hd__be_mg_unavailable(const hd__view *vw) { (void)vw; return NULL; }

static size_t hd__be_solver_bytes(const hd__view *vw)
{
    const struct hd__cpu_mg *mg = vw->be->mg;
    size_t b = 0;
    int l;
    if (!mg || vw->params.solver != HD_SOLVER_MULTIGRID) return 0;
    b += 2 * sizeof(double) * (size_t)mg->lv[0].dims[1] * mg->lv[0].dims[2] * (size_t)mg->channels; /* row sums */
    b += 2 * hd__mg_slots(mg->lv[0].dims, mg->channels) * sizeof(float);                             /* p, lo */
    for (l = 0; l < mg->levels; ++l) {
        b += hd__mg_slots(mg->lv[l].dims, mg->channels) * 3 * sizeof(float); /* rhs, phi, res */
        if (l > 0) b += hd__mg_slots(mg->lv[l].dims, mg->sig_channels) * sizeof(float);
    }
    return b;
}

/* Level l's parameter block and kernel context: the fine block with the level's dims, 1 / h^2
   and h, and the right-hand-side flag; its buffers (level 0: the backend's sigma_t). */
static void hd__cpu_mg_params(const hd__view *vw, int l)
{
    hd__cpu_level *L = &vw->be->mg->lv[l];
    L->kp = hd__mg_level_kp(&vw->kp, l, L->dims);
    L->k = vw->be->k;
    L->k.p = &L->kp;
    L->k.sig = l == 0 ? vw->be->sig : L->sig;
    L->k.E = L->rhs;
    L->k.phi = L->phi;
    L->k.phi2 = NULL;
    L->k.f16 = 0;
    L->g.k = &L->k;
    L->g.res = L->res;
}

/* The fine grid's two extra passes: f - A phi with the backend's own context into r, and A p
   (level 0's context with E = z, which is zero when it runs, and phi = p) into level 0's res. */
static void hd__cpu_mg_fine_params(const hd__view *vw)
{
    struct hd__cpu_mg *mg = vw->be->mg;
    mg->fineg.k = &vw->be->k;
    mg->fineg.res = mg->lv[0].rhs;
    mg->opkp = mg->lv[0].kp;
    mg->opk = mg->lv[0].k;
    mg->opk.p = &mg->opkp;
    mg->opk.E = mg->lv[0].phi;
    mg->opk.phi = mg->p;
    mg->opg.k = &mg->opk;
    mg->opg.res = mg->lv[0].res;
}

/* Allocates the levels and CG's vectors for the current grid, channels and sigma_t channels. */
static hd_result hd__cpu_mg_alloc(const hd__view *vw)
{
    hd__backend *be = vw->be;
    struct hd__cpu_mg *mg;
    int l, n, d[3], i;
    size_t rows, fine;
    be->mg = mg = (struct hd__cpu_mg *)hd__calloc(vw, 1, sizeof *mg);
    if (!mg) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate the multigrid levels");
    mg->channels = vw->channels;
    mg->sig_channels = vw->sig_channels;
    for (i = 0; i < 3; ++i) mg->fine[i] = d[i] = vw->gdims[i];
    rows = (size_t)d[1] * d[2] * (size_t)mg->channels;
    fine = hd__mg_slots(d, mg->channels);
    mg->dot_a = (double *)hd__calloc(vw, rows, sizeof(double));
    mg->dot_b = (double *)hd__calloc(vw, rows, sizeof(double));
    mg->p = (float *)hd__calloc(vw, fine, sizeof(float));
    mg->lo = (float *)hd__calloc(vw, fine, sizeof(float));
    if (!mg->dot_a || !mg->dot_b || !mg->p || !mg->lo) {
        hd__cpu_mg_free(vw);
        return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate the conjugate gradients' vectors");
    }
    for (l = 0, n = hd__mg_levels(mg->fine); l < n; ++l) {
        hd__cpu_level *L = &mg->lv[l];
        size_t v;
        hd__mg_level_dims(mg->fine, l, d);
        v = hd__mg_slots(d, mg->channels);
        memcpy(L->dims, d, sizeof d);
        mg->levels = l + 1;
        L->res = (float *)hd__calloc(vw, v, sizeof(float));
        L->rhs = (float *)hd__calloc(vw, v, sizeof(float));
        L->phi = (float *)hd__calloc(vw, v, sizeof(float));
        if (l > 0) L->sig = (float *)hd__calloc(vw, hd__mg_slots(d, mg->sig_channels), sizeof(float));
        if (!L->res || !L->rhs || !L->phi || (l > 0 && !L->sig)) {
            hd__cpu_mg_free(vw);
            return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate multigrid level %d (%dx%dx%d)", l,
                           d[0], d[1], d[2]);
        }
    }
    return HD_SUCCESS;
}

/* ---- transfers, one coarse row (or fine row) per item ------------------------------------------- */
/* The per-voxel math is the shared kernel's (backends/kernels/hd_k_multigrid.h, with the OpenCL
   backend); these rows run it on a copy of a level's kernel context whose f16 is a literal 0 (the
   levels are float32: no per-load precision test, hd_prelude_c.h's HD_GET) and whose phi is the
   grid the function reads. */

/* sigma_t (all its channels) of level mg->cur from the level above (hdk_mg_coarse_sig). */
static HD__CPU_FLATTEN void hd__cpu_mg_sig_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    hd__cpu_level *C = &mg->lv[mg->cur];
    hd__kctx k = mg->lv[mg->cur - 1].k;
    int Y = r % C->dims[1], Z = (r / C->dims[1]) % C->dims[2], ch = r / (C->dims[1] * C->dims[2]), X;
    k.f16 = 0;
    for (X = 0; X < C->dims[0]; ++X)
        C->sig[hd__split_slot(C->dims[0], C->dims[1], X, Y, Z + ch * C->dims[2])] = hdk_mg_coarse_sig(&k, X, Y, Z, ch);
}

/* Row (y, zz) of a grid of dims gx, gy in the colour layout into out[] in x order: its two
   colour half-rows, each unit-stride (a load by coordinates would alternate between them). */
static void hd__cpu_mg_load_row(const float *buf, int gx, int gy, int y, int zz, float *out)
{
    int h, i, n;
    for (h = 0; h < 2; ++h) {
        const float *src = buf + hd__split_slot(gx, gy, h, y, zz);
        n = hd__cpu_half_len(gx, h);
        for (i = 0; i < n; ++i) out[2 * i + h] = src[i];
    }
}

/* The right-hand side of level mg->cur: R = P^T / 8 of the residual of the level above
   (hd_k_multigrid.h), each fine column's share of the row computed once (hdk_mg_restrict_line's
   terms, hdk_mg_restrict_term, on each of the up to 16 fine rows loaded once, in its a, b order)
   and four of them combined per coarse voxel (hdk_mg_restrict_x); its phi (the correction)
   starts at 0. */
static HD__CPU_FLATTEN void hd__cpu_mg_restrict_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    hd__cpu_level *C = &mg->lv[mg->cur], *F = &mg->lv[mg->cur - 1];
    int Y = r % C->dims[1], Z = (r / C->dims[1]) % C->dims[2], ch = r / (C->dims[1] * C->dims[2]), X, x, t, a, b;
    int gx = F->dims[0], gy = F->dims[1], gz = F->dims[2];
    hd__kctx k = F->k;
    float line[HD__CPU_ROW_MAX], res[HD__CPU_ROW_MAX], m[HD__CPU_ROW_MAX];
    k.f16 = 0;
    for (x = 0; x < gx; ++x) line[x] = 0.0f;
    for (a = 0; a < 4; ++a) {
        int z = 2 * Z - 1 + a;
        if (z < 0 || z >= gz) continue;
        for (b = 0; b < 4; ++b) {
            int y = 2 * Y - 1 + b;
            if (y < 0 || y >= gy) continue;
            hd__cpu_mg_load_row(F->res, gx, gy, y, z + ch * gz, res);
            hd__cpu_mg_load_row(k.sig, gx, gy, y, z, m);
            for (x = 0; x < gx; ++x) line[x] = hdk_mg_restrict_term(line[x], a, b, res[x], hdk_mg_medium_of(&k, m[x]));
        }
    }
    for (X = 0; X < C->dims[0]; ++X) {
        float s = 0.0f;
        for (t = 0; t < 4; ++t) {
            x = 2 * X - 1 + t;
            if (x >= 0 && x < gx) s = hdk_mg_restrict_x(s, t, line[x]);
        }
        size_t o = hd__split_slot(C->dims[0], C->dims[1], X, Y, Z + ch * C->dims[2]);
        C->rhs[o] = s;
        C->phi[o] = 0.0f;
    }
}

/* Adds the prolonged correction of level mg->cur (hdk_mg_prolong's terms, hdk_mg_prolong_term, on
   the up to 4 coarse rows loaded once), masked to the medium (hdk_mg_medium_of the level above's
   sigma_t), to row r of the level above. */
static HD__CPU_FLATTEN void hd__cpu_mg_prolong_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    const hd__cpu_level *F = &mg->lv[mg->cur - 1], *C = &mg->lv[mg->cur];
    hd__kctx kf = F->k;
    int gx = F->dims[0], gy = F->dims[1], gz = F->dims[2], y = r % gy, z = (r / gy) % gz, c = r / (gy * gz);
    int GX = C->dims[0], GY = C->dims[1], GZ = C->dims[2], x, a, b, t, h, i, n;
    int zc[2], yc[2];
    float e[HD__CPU_ROW_MAX], m[HD__CPU_ROW_MAX], u[2][2][HD__CPU_ROW_MAX / 2 + 1];
    kf.f16 = 0;
    zc[0] = z >> 1;
    zc[1] = hdk_mg_far(z);
    yc[0] = y >> 1;
    yc[1] = hdk_mg_far(y);
    for (a = 0; a < 2; ++a)
        for (b = 0; b < 2; ++b)
            if (zc[a] >= 0 && zc[a] < GZ && yc[b] >= 0 && yc[b] < GY)
                hd__cpu_mg_load_row(C->phi, GX, GY, yc[b], zc[a] + c * GZ, u[a][b]);
    hd__cpu_mg_load_row(kf.sig, gx, gy, y, z, m);
    for (x = 0; x < gx; ++x) {
        int xc[2];
        float v = 0.0f;
        xc[0] = x >> 1;
        xc[1] = hdk_mg_far(x);
        for (a = 0; a < 2; ++a) {
            if (zc[a] < 0 || zc[a] >= GZ) continue;
            for (b = 0; b < 2; ++b) {
                if (yc[b] < 0 || yc[b] >= GY) continue;
                for (t = 0; t < 2; ++t)
                    if (xc[t] >= 0 && xc[t] < GX) v = hdk_mg_prolong_term(v, a, b, t, u[a][b][xc[t]]);
            }
        }
        e[x] = v * hdk_mg_medium_of(&kf, m[x]);
    }
    for (h = 0; h < 2; ++h) {
        float *dst = F->phi + hd__split_slot(gx, gy, h, y, z + c * gz);
        n = hd__cpu_half_len(gx, h);
        for (i = 0; i < n; ++i) dst[i] += e[2 * i + h];
    }
}

static int hd__mg_rows(const hd__cpu_level *L, int channels) { return L->dims[1] * L->dims[2] * channels; }

/* ---- the fine residual in double ------------------------------------------------------------------ */
/* f - A (phi + lo) of row r (= (c * gz + z) * gy + y) of be->grid into out[], evaluated in double
   by the shared hdk_mg_res_f64 (hd_k_multigrid.h says why), stored as float; lo (the iterate's low
   part) only on the fine grid of the iterate (mg->fineg). Literal in-grid flags, boundary and RGB
   for the interior voxels, so each variant's loop has no test. */
static HD__CPU_FLATTEN void hd__cpu_mg_residual_f64_into(const hd__backend *be, int r, float *out)
{
    hd__kctx k = *be->grid->k;
    const hd__kctx *K = &k;
    int lo = be->mg && be->grid == &be->mg->fineg;
    int gx = K->p->gdims.x, gy = K->p->gdims.y, gz = K->p->gdims.z, x;
    int y = r % gy, z = (r / gy) % gz, c = r / (gy * gz);
    int surface = (K->p->counts.z & HD_FLAG_SURFACE_BOUNDARY) != 0, rgb = (K->p->counts.z & HD_FLAG_RGB_SCATTERING) != 0;
    int edge = gx < 3 || y == 0 || y == gy - 1 || z == 0 || z == gz - 1;
    k.f16 = 0;
    k.phi2 = lo ? be->mg->lo : NULL;
    for (x = 0; x < gx; ++x) {
        int ix = x > 0 && x < gx - 1;
        if (edge || !ix)
            out[x] = (float)hdk_mg_res_f64(K, x, y, z, c, surface, rgb, lo, x > 0, x < gx - 1, y > 0, y < gy - 1, z > 0, z < gz - 1);
        else if (lo)
            out[x] = (float)(surface ? (rgb ? hdk_mg_res_f64(K, x, y, z, c, 1, 1, 1, 1, 1, 1, 1, 1, 1)
                                            : hdk_mg_res_f64(K, x, y, z, c, 1, 0, 1, 1, 1, 1, 1, 1, 1))
                                     : (rgb ? hdk_mg_res_f64(K, x, y, z, c, 0, 1, 1, 1, 1, 1, 1, 1, 1)
                                            : hdk_mg_res_f64(K, x, y, z, c, 0, 0, 1, 1, 1, 1, 1, 1, 1)));
        else
            out[x] = (float)(surface ? (rgb ? hdk_mg_res_f64(K, x, y, z, c, 1, 1, 0, 1, 1, 1, 1, 1, 1)
                                            : hdk_mg_res_f64(K, x, y, z, c, 1, 0, 0, 1, 1, 1, 1, 1, 1))
                                     : (rgb ? hdk_mg_res_f64(K, x, y, z, c, 0, 1, 0, 1, 1, 1, 1, 1, 1)
                                            : hdk_mg_res_f64(K, x, y, z, c, 0, 0, 0, 1, 1, 1, 1, 1, 1)));
    }
}

/* Row r (= zz * gy + y) of a grid in the colour layout of dims d: from row[] (x in order) into
   buf's slots, one unit-stride colour half-row at a time. */
static void hd__cpu_mg_scatter_row(const hd__kparams *d, float *buf, int r, const float *row)
{
    int gx = d->gdims.x, gy = d->gdims.y, h, i, n;
    for (h = 0; h < 2; ++h) {
        float *dst = buf + hd__split_slot(gx, gy, h, r % gy, r / gy);
        n = hd__cpu_half_len(gx, h);
        for (i = 0; i < n; ++i) dst[i] = row[2 * i + h];
    }
}

/* The residual of row r of be->grid into its res. */
static void hd__cpu_mg_residual_f64_row(hd__backend *be, int r)
{
    float out[HD__CPU_ROW_MAX];
    hd__cpu_mg_residual_f64_into(be, r, out);
    hd__cpu_mg_scatter_row(be->grid->k->p, be->grid->res, r, out);
}

/* ---- conjugate gradients' passes over the fine rows --------------------------------------------- */
/* <a, b> of row r of level 0 (hdk_mg_dot_row's terms, hdk_mg_dot_term: in double, x in order) on
   the two rows loaded once (loads by coordinates are gathers in the colour layout). */
static double hd__cpu_mg_dot(const hd__backend *be, int r, const float *a, const float *b)
{
    const int *d = be->mg->lv[0].dims;
    float ra[HD__CPU_ROW_MAX], rb[HD__CPU_ROW_MAX];
    double s = 0.0;
    int x;
    hd__cpu_mg_load_row(a, d[0], d[1], r % d[1], r / d[1], ra);
    hd__cpu_mg_load_row(b, d[0], d[1], r % d[1], r / d[1], rb);
    for (x = 0; x < d[0]; ++x) s = hdk_mg_dot_term(s, ra[x], rb[x]);
    return s;
}

/* The half-row of x parity h of fine row r (= zz * gy + y) of the colour layout: its first slot,
   and its length in *n. The element-wise passes below walk a row as its two halves (every voxel
   once, the padding slot never). */
static size_t hd__cpu_mg_half(const hd__backend *be, int r, int h, int *n)
{
    const int *d = be->mg->lv[0].dims;
    *n = hd__cpu_half_len(d[0], h);
    return hd__split_slot(d[0], d[1], h, r % d[1], r / d[1]);
}

/* dot_a[r] = <r, z> of row r. */
static void hd__cpu_mg_rz_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    mg->dot_a[r] = hd__cpu_mg_dot(be, r, mg->lv[0].rhs, mg->lv[0].phi);
}

/* p = z + beta p, then z = 0 (the next V-cycle's start, and A p's zero right-hand side). */
static void hd__cpu_mg_dir_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    int i, h, n;
    float beta = mg->beta;
    for (h = 0; h < 2; ++h) {
        size_t o = hd__cpu_mg_half(be, r, h, &n);
        float *z = mg->lv[0].phi + o, *p = mg->p + o;
        for (i = 0; i < n; ++i) {
            p[i] = hdk_mg_dir_of(z[i], p[i], beta);
            z[i] = 0.0f;
        }
    }
}

/* q = A p (minus the residual of p with a zero right-hand side, in double: p is smooth, A p
   much smaller than den p, and the float kernel's cancellation made alpha wrong once the
   residual neared 1e-4) into level 0's res;
   dot_a[r] = <p, q>, dot_b[r] = <r, p>. */
static void hd__cpu_mg_op_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    int x, gx = mg->lv[0].dims[0];
    float q[HD__CPU_ROW_MAX];
    hd__cpu_mg_residual_f64_into(be, r, q);
    for (x = 0; x < gx; ++x) q[x] = -q[x];
    hd__cpu_mg_scatter_row(&mg->lv[0].kp, mg->lv[0].res, r, q);
    mg->dot_a[r] = hd__cpu_mg_dot(be, r, mg->p, mg->lv[0].res);
    mg->dot_b[r] = hd__cpu_mg_dot(be, r, mg->lv[0].rhs, mg->p);
}

/* phi + lo += alpha p in double (hdk_mg_update_of): phi is the sum rounded to float, lo the rest. */
static void hd__cpu_mg_update_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    int i, h, n;
    double alpha = mg->alpha;
    for (h = 0; h < 2; ++h) {
        size_t o = hd__cpu_mg_half(be, r, h, &n);
        float *phi = be->phi + o, *lo = mg->lo + o;
        const float *p = mg->p + o;
        for (i = 0; i < n; ++i) phi[i] = hdk_mg_update_of(phi[i], &lo[i], p[i], alpha);
    }
}

/* Empty voxels of the surface boundary, colour mg->colour, of row r: phi = the extrapolation the
   sweeps store there (hdk_diffuse_extrapolate, read by the projection), lo = -phi, so CG's iterate
   phi + lo stays exactly 0 on those identity rows (hdk_mg_res_f64's -(phi + lo); z and so p are 0
   there, the V-cycle's rows being identity rows too). */
static HD__CPU_FLATTEN void hd__cpu_mg_extrap_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    int gx = mg->lv[0].dims[0], gy = mg->lv[0].dims[1], gz = mg->lv[0].dims[2], x;
    int y = r % gy, z = (r / gy) % gz, c = r / (gy * gz);
    float v = 0.0f;
    for (x = (y + z + mg->colour) & 1; x < gx; x += 2)
        if (hdk_diffuse_extrapolate(&be->k, x, y, z, c, &v)) {
            size_t s = hd__split_slot(gx, gy, x, y, z + c * gz);
            be->phi[s] = v;
            mg->lo[s] = -v;
        }
}

/* ---- the primitives (src/hd_backend.h) -------------------------------------------------------- */
static hd_result hd__be_mg_begin(const hd__view *vw, int *fresh)
{
    hd__backend *be = vw->be;
    struct hd__cpu_mg *mg = be->mg;
    hd_result r;
    int l;
    if (mg && (mg->channels != vw->channels || mg->sig_channels != vw->sig_channels ||
               memcmp(mg->fine, vw->gdims, sizeof mg->fine) != 0))
        hd__cpu_mg_free(vw);
    *fresh = !be->mg;
    if (!be->mg && (r = hd__cpu_mg_alloc(vw)) != HD_SUCCESS) return r;
    mg = be->mg;
    for (l = 0; l < mg->levels; ++l) hd__cpu_mg_params(vw, l);
    hd__cpu_mg_fine_params(vw);
    return HD_SUCCESS;
}

static hd_result hd__be_mg_end(const hd__view *vw, hd_result r)
{
    vw->be->grid = NULL;
    return r;
}

static hd_result hd__be_mg_coarsen(const hd__view *vw, int l)
{
    struct hd__cpu_mg *mg = vw->be->mg;
    mg->cur = l;
    hd__cpu_parallel(vw->be, hd__cpu_mg_sig_row, mg->lv[l].dims[1] * mg->lv[l].dims[2] * mg->sig_channels);
    return HD_SUCCESS;
}

static hd_result hd__be_mg_zero_lo(const hd__view *vw)
{
    struct hd__cpu_mg *mg = vw->be->mg;
    memset(mg->lo, 0, hd__mg_slots(mg->fine, mg->channels) * sizeof(float));
    return HD_SUCCESS;
}

/* One pass of job over the rows of every channel of level l (0: the finest). */
static void hd__cpu_mg_pass(hd__backend *be, hd__cpu_job job, int l)
{
    hd__cpu_parallel(be, job, hd__mg_rows(&be->mg->lv[l], be->mg->channels));
}

static hd_result hd__be_mg_residual_f64(const hd__view *vw)
{
    hd__backend *be = vw->be;
    be->grid = &be->mg->fineg;
    hd__cpu_mg_pass(be, hd__cpu_mg_residual_f64_row, 0);
    return HD_SUCCESS;
}

static hd_result hd__be_mg_smooth(const hd__view *vw, int l, int sweeps, int first)
{
    hd__backend *be = vw->be;
    be->grid = &be->mg->lv[l].g;
    hd__cpu_red_black(be, sweeps, first);
    return HD_SUCCESS;
}

static hd_result hd__be_mg_residual(const hd__view *vw, int l)
{
    hd__backend *be = vw->be;
    be->grid = &be->mg->lv[l].g;
    hd__cpu_mg_pass(be, hd__cpu_residual_row, l);
    return HD_SUCCESS;
}

static hd_result hd__be_mg_restrict(const hd__view *vw, int l)
{
    hd__backend *be = vw->be;
    be->mg->cur = l + 1;
    hd__cpu_mg_pass(be, hd__cpu_mg_restrict_row, l + 1);
    return HD_SUCCESS;
}

static hd_result hd__be_mg_prolong(const hd__view *vw, int l)
{
    hd__backend *be = vw->be;
    be->mg->cur = l + 1;
    hd__cpu_mg_pass(be, hd__cpu_mg_prolong_row, l);
    return HD_SUCCESS;
}

static hd_result hd__be_mg_dot_rz(const hd__view *vw)
{
    hd__cpu_mg_pass(vw->be, hd__cpu_mg_rz_row, 0);
    return HD_SUCCESS;
}

static hd_result hd__be_mg_direction(const hd__view *vw, float beta)
{
    vw->be->mg->beta = beta;
    hd__cpu_mg_pass(vw->be, hd__cpu_mg_dir_row, 0);
    return HD_SUCCESS;
}

/* q and both dot products in one pass over the rows (hd__cpu_mg_op_row). */
static hd_result hd__be_mg_apply(const hd__view *vw)
{
    hd__backend *be = vw->be;
    be->grid = &be->mg->opg;
    hd__cpu_mg_pass(be, hd__cpu_mg_op_row, 0);
    be->grid = NULL;
    return HD_SUCCESS;
}

/* The passes ran to completion in hd__cpu_parallel: the row sums are the host's. */
static hd_result hd__be_mg_row_sums(const hd__view *vw, int n, const double **a, const double **b)
{
    (void)n;
    *a = vw->be->mg->dot_a;
    *b = vw->be->mg->dot_b;
    return HD_SUCCESS;
}

static hd_result hd__be_mg_update(const hd__view *vw, double alpha)
{
    vw->be->mg->alpha = alpha;
    hd__cpu_mg_pass(vw->be, hd__cpu_mg_update_row, 0);
    return HD_SUCCESS;
}

static hd_result hd__be_mg_extrapolate(const hd__view *vw, int colour)
{
    vw->be->mg->colour = colour;
    hd__cpu_mg_pass(vw->be, hd__cpu_mg_extrap_row, 0);
    return HD_SUCCESS;
}
