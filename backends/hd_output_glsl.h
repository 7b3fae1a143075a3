/* hd_output_glsl.h - GLSL text, not C: the output pass of hd_gl_render_to_texture(_ex) (GL 4.30,
   embedded by scripts/embed-glsl as hd__gl_source_output) and hd_vulkan_record_render (Vulkan,
   SPIR-V hd__spv_output from scripts/build-spirv, with HD_OUTPUT_VULKAN defined). It encodes the
   float RGBA image (img: hd_op.x by hd_op.y pixels, top row first) in an output format
   (hybriddiff.h, hd_output_format; hd_op.z) into packed words (o), row after row, which a transfer
   then copies into the caller's texture, image or buffer (glTexSubImage2D from a pixel unpack
   buffer, vkCmdCopyBufferToImage, vkCmdCopyBuffer). hd_op.w: bit 0 writes the rows bottom first
   (GL's texel order), bit 1 swaps R and B (a BGRA target). hd_o_exposure scales rgb.
   The bytes are exactly hd_read_image_ex's (src/hd_readback.h): the products rgb * exposure are
   IEEE multiplications, correctly rounded on the device as on the host (`precise`: no
   contraction into anything else); HD_OUTPUT_LINEAR_F16 converts by hdk_f2h's integer steps
   (hd_prelude_c.h), not by the driver's conversion (llvmpipe and lavapipe truncate); RGBA8
   counts the thresholds of hd__output_thresholds (src/hd_backend.h, computed on the host from
   hd__srgb8 and hd__alpha8) at or below each value, a binary search, so no pow runs here. */
layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;
#ifdef HD_OUTPUT_VULKAN
layout(std430, binding = 0) readonly buffer hd_o_img { float img[]; };
layout(std430, binding = 1) readonly buffer hd_o_tab { float otab[]; };
layout(std430, binding = 2) writeonly buffer hd_o_out { uint o[]; };
layout(push_constant) uniform hd_o_push { ivec4 hd_op; float hd_o_exposure; };
#else
layout(std430, binding = 2) readonly buffer hd_o_img { float img[]; };
layout(std430, binding = 0) readonly buffer hd_o_tab { float otab[]; };
layout(std430, binding = 1) writeonly buffer hd_o_out { uint o[]; };
layout(location = 0) uniform ivec4 hd_op;
layout(location = 1) uniform float hd_o_exposure;
#endif

/* hdk_f2h (hd_prelude_c.h): nearest binary16, ties to even; >= 65520 inf; NaN quiet. The
   subnormal case adds 0.5 so the float adder rounds (correctly rounded in GLSL and SPIR-V). */
uint hd_o_f2h(float f)
{
    uint u = floatBitsToUint(f), sign = (u >> 16) & 0x8000u, a = u & 0x7fffffffu;
    uint special = a > 0x7f800000u ? (0x7e00u | ((a >> 13) & 0x3ffu)) : 0x7c00u;
    uint normal = (a - (112u << 23) + 0x0fffu + ((a >> 13) & 1u)) >> 13;
    precise float s = uintBitsToFloat(a) + 0.5;
    uint sub = floatBitsToUint(s) - 0x3f000000u;
    uint h = a >= 0x477ff000u ? special : (a >= 0x38800000u ? normal : sub);
    return sign | h;
}

/* The RGBA8 code of v: how many of the 255 thresholds otab[base .. base + 254] (ascending) are
   <= v; NaN: 0. */
uint hd_o_code(float v, int base)
{
    int lo = 0, hi = 255;
    while (lo < hi) {
        int mid = (lo + hi) >> 1;
        if (otab[base + mid] <= v) lo = mid + 1;
        else hi = mid;
    }
    return uint(lo);
}

void main()
{
    int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y);
    if (x >= hd_op.x || y >= hd_op.y) return;
    int row = (hd_op.w & 1) != 0 ? hd_op.y - 1 - y : y;
    int i = 4 * (row * hd_op.x + x), p = y * hd_op.x + x;
    precise float r = img[i] * hd_o_exposure;
    precise float g = img[i + 1] * hd_o_exposure;
    precise float b = img[i + 2] * hd_o_exposure;
    float a = img[i + 3];
    if ((hd_op.w & 2) != 0) {
        float t = r;
        r = b;
        b = t;
    }
    if (hd_op.z == 0) {
        o[p] = hd_o_code(r, 0) | (hd_o_code(g, 0) << 8) | (hd_o_code(b, 0) << 16) | (hd_o_code(a, 255) << 24);
    } else if (hd_op.z == 1) {
        o[2 * p] = hd_o_f2h(r) | (hd_o_f2h(g) << 16);
        o[2 * p + 1] = hd_o_f2h(b) | (hd_o_f2h(a) << 16);
    } else {
        o[4 * p] = floatBitsToUint(r);
        o[4 * p + 1] = floatBitsToUint(g);
        o[4 * p + 2] = floatBitsToUint(b);
        o[4 * p + 3] = floatBitsToUint(a);
    }
}
