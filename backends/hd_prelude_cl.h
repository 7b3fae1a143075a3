/* hd_prelude_cl.h - OpenCL C 1.2 text, not C: makes the shared kernel sources (backends/kernels/)
   valid OpenCL C, defining the same names as hd_prelude_c.h (read that file for what each means).
   scripts/embed-kernels turns this file, the shared kernels and hd_entry_cl.h into string
   literals in hd_kernels_embedded.h, which hd_opencl.h compiles at run time. The host passes
   -DHD_MAX_LIGHTS=n, so the parameter block has one definition of its size. */
/* Forced inlining: PoCL's compiler left hd_diffuse_terms_at, hdk_track and hdk_sample_value as
   calls, and a call in a work-item loop keeps it from vectorising that loop (the diffusion). */
#define HD_FN inline __attribute__((always_inline))
#define HD_LANG_CL 1
/* The C reference does not fuse a*b+c (ISO C modes, -std=c99, default to -ffp-contract=off);
   OpenCL C would by default. Off, so the deterministic stages round exactly as the CPU does.
   The projection is its own program (hd_opencl.h builds this source twice; HD_CL_PROJECTION_PROGRAM
   keeps only its entry points) with fusion on: its image is a mean of jittered frames, not
   compared bit for bit, and the march's lerps and interpolations fused into FMAs cost PoCL a
   fifth less CPU time per frame (docs/PERFORMANCE.md); the image moves by float rounding only. */
#ifdef HD_CL_PROJECTION_PROGRAM
#pragma OPENCL FP_CONTRACT ON
#else
#pragma OPENCL FP_CONTRACT OFF
#endif

typedef uint hd_u32;
typedef float3 hd_v3;
typedef float4 hd_v4;
typedef int4 hd_i4;
typedef float4 hd_f4;

#define HD_F(v) ((float)(v))
#define HD_I(v) ((int)(v))
#define HD_U(v) ((hd_u32)(v))

#define HD_V3(x, y, z) ((float3)((x), (y), (z)))
#define HD_V4(x, y, z, w) ((float4)((x), (y), (z), (w)))
#define HD_XYZ(v4) ((v4).xyz)
HD_FN hd_v3 hdk_add(hd_v3 a, hd_v3 b) { return a + b; }
HD_FN hd_v3 hdk_sub(hd_v3 a, hd_v3 b) { return a - b; }
HD_FN hd_v3 hdk_scale(hd_v3 a, float s) { return a * s; }
HD_FN hd_v3 hdk_vmul(hd_v3 a, hd_v3 b) { return a * b; }
HD_FN hd_v3 hdk_vdiv(hd_v3 a, hd_v3 b) { return a / b; }
HD_FN hd_v3 hdk_madd(hd_v3 p, hd_v3 d, float t) { return p + d * t; }
/* Spelled out, not dot(): the same order of operations as the C prelude. */
HD_FN float hdk_dot(hd_v3 a, hd_v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
HD_FN float hdk_len(hd_v3 a) { return sqrt(hdk_dot(a, a)); }
HD_FN hd_v3 hdk_normalize(hd_v3 a) { return hdk_scale(a, 1.0f / hdk_len(a)); }

/* PoCL's log() is SLEEF's scalar 1-ulp logf (double-float arithmetic): 3.2x the time of glibc's
   logf and a third of the direct-light stage. This is the FreeBSD/musl logf (< 1 ulp, the same
   class as glibc's), inlined; zero, negative, subnormal, inf and NaN arguments go to log(). */
HD_FN float hdk_log(float x)
{
    uint ix = as_uint(x);
    int k;
    float f, s, z, w, r, hfsq, dk;
    if (ix - 0x00800000u >= 0x7f000000u) return log(x);
    ix += 0x3f800000u - 0x3f3504f3u;
    k = (int)(ix >> 23) - 0x7f;
    ix = (ix & 0x007fffffu) + 0x3f3504f3u;
    f = as_float(ix) - 1.0f;
    s = f / (2.0f + f);
    z = s * s;
    w = z * z;
    r = z * (0.66666662693f + w * 0.28498786688f) + w * (0.40000972152f + w * 0.24279078841f);
    hfsq = 0.5f * f * f;
    dk = (float)k;
    return s * (hfsq + r) + dk * 9.0580006145e-06f - hfsq + f + dk * 6.9313812256e-01f;
}
#define hdk_exp(x) exp(x)
#define hdk_sqrt(x) sqrt(x)
#define hdk_floor(x) floor(x)
#define hdk_absf(x) fabs(x)
#define hdk_powf(x, y) pow((x), (y))
HD_FN float hdk_minf(float a, float b) { return a < b ? a : b; }
HD_FN float hdk_maxf(float a, float b) { return a > b ? a : b; }
HD_FN int hdk_mini(int a, int b) { return a < b ? a : b; }
HD_FN int hdk_maxi(int a, int b) { return a > b ? a : b; }
HD_FN float hdk_clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
HD_FN int hdk_clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

#define HD_STRUCT(name) typedef struct name {
#define HD_STRUCT_END(name) } name;

/* Output parameters: pointers to private memory. */
#define HD_INOUT(type) type *
#define HD_DEREF(p) (*(p))
#define HD_REF(v) (&(v))

/* The parameter block lives in a __constant buffer; int4/float4 are 16-byte aligned like the
   C prelude's structs of four 32-bit members, so the offsets agree. */
#define HD_PARAM_I4(name) int4 name;
#define HD_PARAM_F4(name) float4 name;
#define HD_PARAM_F4_ARRAY(name, n) float4 name[n];
#define HD_PARAMS_BEGIN typedef struct hd__kparams {
#define HD_PARAMS_END } hd__kparams;

/* What a kernel invocation reaches through K: a private struct of pointers, filled by the
   __kernel entry points in hd_entry_cl.h. */
typedef struct hd__kctx {
    __constant struct hd__kparams *p;
    __global const float *vol;  /* the volume as p->vstore.x stores it (HD_VOL_RAW reads it) */
    __global const float *tf;
    __global const float *maj;
    __global float *sig;
    __global float *E;
    __global float *phi;
    __global float *phi2;
    /* E, phi, phi2 as binary16 (params.illumination_precision FLOAT16): the same buffers seen
       as half, read and written through vload_half / vstore_half_rte, core OpenCL C 1.2 (no
       cl_khr_fp16: the arithmetic stays float); f16 says which view HD_GET uses. The entry
       points set it as a literal, so the compiler keeps one of the two. */
    __global half *Eh;
    __global half *phih;
    __global half *phi2h;
    int f16;
    __global float *img;
    __global float *lsum;       /* projection: E + phi, x-fastest (hdk_light_sum_voxel) */
    __global const float *ptab; /* projection: the step's TF table, ptab_n RGBA entries */
    int ptab_n;
    __global const float *dep;  /* the host's depth buffer (hd_set_depth; projection and paths) */
    __global const float *env;  /* the environment's tables (hd_set_environment; direct light and paths) */
    __global const float *lv;   /* CD: the light volume being read */
    __global float *lv2;        /* CD: the light volume being written */
    int flags;                  /* what the diffusion reads as HD_DIFFUSE_FLAGS */
    /* The colour-separated layout of sig, E, phi, phi2 (see HD_GET): hx = (gx + 1) / 2, the
       length of a packed half-row; gy the grid's rows. In the diffusion, cx is the work-item's
       x, cp = cx & 1 and cid = cx >> 1 its packed index (so addresses are affine in it); in every
       other kernel all three are 0 and the same formula gives any voxel's place. */
    int hx, gy, cx, cp;
    size_t cid;
} hd__kctx;

/* Voxel i of the volume as stored (t: HD_VOL_* of hd_k_params.h, which comes after this file:
   1 U8, 2 U16, 3 I16, 0 F32): the raw integer, or the F32 volume's value. */
HD_FN float hd__cl_vol_raw(const hd__kctx *K, int i, int t)
{
    return t == 1 ? (float)((__global const uchar *)K->vol)[i]
         : t == 2 ? (float)((__global const ushort *)K->vol)[i]
         : t == 3 ? (float)((__global const short *)K->vol)[i] : K->vol[i];
}

/* The projection reads the summed light grid and the step's TF table (hd_k_project.h); the
   backend keeps both up to date before every projection. */
#define HD_PRELUDE_LIGHT_SUM 1
#define HD_LIGHT_SUM_READY 1
#define HD_PRELUDE_PROJECT_TABLE 1
#define HD_PROJECT_TABLE_READY 1
#define HD_PTAB_N (K->ptab_n)

/* The diffusion's flags come from K, so a kernel can make them literals (hd_entry_cl.h). */
#define HD_DIFFUSE_FLAGS (K->flags)

#define HD_KARGS const hd__kctx *K,
#define HD_KPASS K,
#define HD_PRM(name) (K->p->name)
/* Grid reads and writes. The volume (vol) and CD's light volumes (lv, lv2) are x-fastest,
   element i = (z * gy + y) * gx + x. The buffers the diffusion reads (sig with its RGB channels,
   E, phi, phi2) are stored colour by colour instead: voxel (x, y, zz), zz = z + c * gz for
   channel c, has colour k = (x + y + zz) & 1 and lives at
       ((zz * 2 + k) * gy + y) * hx + (x >> 1),   hx = (gx + 1) / 2,
   i.e. each z-slice (of each channel) is its colour-0 voxels, row by row, then its colour-1
   voxels; a row of odd gx has one padding slot in one colour. The shared kernels pass every
   voxel's coordinates, so the index i is not used for these buffers. Why: a red-black half-sweep
   updates one colour, and the work-item with packed index id updates x = 2 id + cp; its
   neighbours x - 1, x + 1 (the other colour) sit at id - 1 + cp and id + cp, and y +- 1, z +- 1
   at id, the same offsets for every work-item of the row: contiguous, vectorisable loads, where
   stride-2 accesses in the x-fastest layout became gathers (docs/DESIGN-OPENCL.md). Written with
   d = x - cx, which the compiler folds to the constant -1, 0 or +1 after inlining, the address
   is (buf + cid)[uniform]: affine in the work-item index. Outside the diffusion cx = cp = cid
   = 0 and the same expression is the plain formula above. */
#define HD_GET(buf, i, x, y, z) HD__LD_##buf((i), (x), (y), (z))
#define HD_SET(buf, i, x, y, z, v) HD__ST_##buf((i), (x), (y), (z), (v))
#define HD__CL_D(x) ((x) - K->cx)
#define HD__CL_AT(x, y, zz) \
    ((((zz) * 2 + ((K->cp + HD__CL_D(x) + (y) + (zz)) & 1)) * K->gy + (y)) * K->hx + ((HD__CL_D(x) + K->cp) >> 1))
#define HD__CL_COL(buf, x, y, zz) ((K->buf + K->cid)[HD__CL_AT(x, y, zz)])
#define HD_VOL_RAW(i, x, y, z, t) hd__cl_vol_raw(K, (i), (t))
#define HD__LD_lv(i, x, y, z) (K->lv[(i)])
#define HD__LD_lv2(i, x, y, z) (K->lv2[(i)])
#define HD__LD_lsum(i, x, y, z) (K->lsum[(i)])
#define HD__ST_lsum(i, x, y, z, v) (K->lsum[(i)] = (v))
#define HD__ST_lv2(i, x, y, z, v) (K->lv2[(i)] = (v))
#define HD__LD_sig(i, x, y, z) HD__CL_COL(sig, x, y, z)
#define HD__ST_sig(i, x, y, z, v) (HD__CL_COL(sig, x, y, z) = (v))
/* The illumination buffers: float, or binary16 rounded to nearest even and saturated at 65504
   (as the C prelude's hdk_f2h_sat, so both backends store the same bits for the same float). */
#define HD__LD_HALF(buf, x, y, z) \
    (K->f16 != 0 ? vload_half((size_t)HD__CL_AT(x, y, z), K->buf##h + K->cid) : HD__CL_COL(buf, x, y, z))
#define HD__ST_HALF(buf, x, y, z, v) \
    (K->f16 != 0 ? vstore_half_rte(fmin((v), 65504.0f), (size_t)HD__CL_AT(x, y, z), K->buf##h + K->cid) \
                 : (void)(HD__CL_COL(buf, x, y, z) = (v)))
#define HD__LD_E(i, x, y, z) HD__LD_HALF(E, x, y, z)
#define HD__LD_phi(i, x, y, z) HD__LD_HALF(phi, x, y, z)
#define HD__LD_phi2(i, x, y, z) HD__LD_HALF(phi2, x, y, z)
#define HD__ST_E(i, x, y, z, v) HD__ST_HALF(E, x, y, z, v)
#define HD__ST_phi(i, x, y, z, v) HD__ST_HALF(phi, x, y, z, v)
#define HD__ST_phi2(i, x, y, z, v) HD__ST_HALF(phi2, x, y, z, v)
#define HD_GET1(buf, i) (K->buf[(i)])
#define HD_SET1(buf, i, v) (K->buf[(i)] = (v))
