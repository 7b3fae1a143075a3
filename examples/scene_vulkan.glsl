#version 450
/* scene_vulkan.glsl - examples/scene_vulkan.c's shaders, one stage per macro (mk/scene.mk compiles
   each with glslangValidator -V -S STAGE -DMACRO into the build directory's scene_vulkan_spv.h):
     MESH_VS, MESH_FS   the ground plane and the boxes: Lambert under the sun plus a sky term,
                        the sun inside the cloud's box through the cloud's light
     QUAD_VS            a full-screen triangle
     BLEND_FS           the library's linear premultiplied image, blended ONE, ONE_MINUS_SRC_ALPHA
     TONEMAP_FS         the HDR framebuffer tone-mapped (x / (1 + x)) and sRGB-encoded */

#if defined(MESH_VS)
layout(location = 0) in vec3 pos;
layout(location = 1) in vec3 nrm;
/* mvp, the model matrix's columns with the albedo in the first three's w (128 bytes) */
layout(push_constant) uniform Mesh { mat4 mvp; vec4 m0, m1, m2, m3; } pc;
layout(location = 0) out vec3 n_world;
layout(location = 1) out vec3 albedo;
layout(location = 2) out vec3 p_world;
void main()
{
    mat3 m = mat3(pc.m0.xyz, pc.m1.xyz, pc.m2.xyz);
    n_world = m * nrm; /* the boxes are scaled, not sheared: the normal's direction holds */
    albedo = vec3(pc.m0.w, pc.m1.w, pc.m2.w);
    p_world = m * pos + pc.m3.xyz;
    gl_Position = pc.mvp * vec4(pos, 1.0);
}

#elif defined(MESH_FS)
/* the sun (the direction its light travels in, its radiance): the library's light, given by
   scene_vulkan.c as specialization constants, as are the rows of the cloud's world-to-box
   transform (inverse(volume.transform); the box's largest side is 1) */
layout(constant_id = 0) const float sun_x = 0.0;
layout(constant_id = 1) const float sun_y = -1.0;
layout(constant_id = 2) const float sun_z = 0.0;
layout(constant_id = 3) const float sun_r = 1.0;
layout(constant_id = 4) const float sun_g = 1.0;
layout(constant_id = 5) const float sun_b = 1.0;
layout(constant_id = 6) const float b00 = 1.0;
layout(constant_id = 7) const float b01 = 0.0;
layout(constant_id = 8) const float b02 = 0.0;
layout(constant_id = 9) const float b03 = 0.0;
layout(constant_id = 10) const float b10 = 0.0;
layout(constant_id = 11) const float b11 = 1.0;
layout(constant_id = 12) const float b12 = 0.0;
layout(constant_id = 13) const float b13 = 0.0;
layout(constant_id = 14) const float b20 = 0.0;
layout(constant_id = 15) const float b21 = 0.0;
layout(constant_id = 16) const float b22 = 1.0;
layout(constant_id = 17) const float b23 = 0.0;
/* the cloud's light (E + phi, hd_vulkan_record_illumination), in units of the sun's largest
   colour component: sun_rgb * light / max(sun_rgb) is the sunlight that reaches a point in the
   medium. The grid holds light only where there is medium (0 elsewhere), so it is interpolated
   over the lit texels of the eight around u; none lit: no light from the grid (-1). */
layout(set = 0, binding = 0) uniform sampler3D light;
float medium_light(vec3 u)
{
    ivec3 n = textureSize(light, 0);
    vec3 g = clamp(u * vec3(n) - 0.5, vec3(0.0), vec3(n - 1));
    ivec3 i0 = ivec3(floor(g)), i1 = min(i0 + 1, n - 1);
    vec3 f = g - vec3(i0);
    float sum = 0.0, wsum = 0.0;
    for (int k = 0; k < 8; ++k) {
        ivec3 b = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        float v = texelFetch(light, mix(i0, i1, bvec3(b)), 0).r;
        vec3 w3 = mix(1.0 - f, f, vec3(b));
        float w = w3.x * w3.y * w3.z;
        if (v > 0.0) { sum += w * v; wsum += w; }
    }
    return wsum > 0.0 ? sum / wsum : -1.0;
}
layout(location = 0) in vec3 n_world;
layout(location = 1) in vec3 albedo;
layout(location = 2) in vec3 p_world;
layout(location = 0) out vec4 colour;
void main()
{
    vec3 sun = vec3(sun_r, sun_g, sun_b), u = vec3(dot(vec4(b00, b01, b02, b03), vec4(p_world, 1.0)),
                                                    dot(vec4(b10, b11, b12, b13), vec4(p_world, 1.0)),
                                                    dot(vec4(b20, b21, b22, b23), vec4(p_world, 1.0))) + 0.5;
    float l = max(dot(normalize(n_world), -vec3(sun_x, sun_y, sun_z)), 0.0);
    /* in the cloud's medium the sun comes through the cloud: its shadow and its glow */
    if (all(greaterThanEqual(u, vec3(0.0))) && all(lessThanEqual(u, vec3(1.0)))) {
        float e = medium_light(u);
        if (e >= 0.0) sun *= e / max(sun.r, max(sun.g, sun.b));
    }
    colour = vec4(albedo / 3.14159265 * (sun * l + vec3(0.8, 0.95, 1.25)), 1.0);
}

#elif defined(QUAD_VS)
void main()
{
    vec2 uv = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}

#elif defined(BLEND_FS)
/* texel for texel: the library's image has the framebuffer's size and rows (top first) */
layout(set = 0, binding = 0) uniform sampler2D img;
layout(location = 0) out vec4 colour;
void main() { colour = texelFetch(img, ivec2(gl_FragCoord.xy), 0); }

#elif defined(TONEMAP_FS)
layout(set = 0, binding = 0) uniform sampler2D img;
layout(location = 0) out vec4 colour;
void main()
{
    vec3 c = texelFetch(img, ivec2(gl_FragCoord.xy), 0).rgb;
    c = c / (1.0 + c);
    colour = vec4(mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c)), 1.0);
}
#endif
