#version 450
/* scene_vulkan.glsl - examples/scene_vulkan.c's shaders, one stage per macro (mk/scene.mk compiles
   each with glslangValidator -V -S STAGE -DMACRO into the build directory's scene_vulkan_spv.h):
     MESH_VS, MESH_FS   the ground plane and the boxes: Lambert under the sun plus a sky term
     QUAD_VS            a full-screen triangle
     BLEND_FS           the library's linear premultiplied image, blended ONE, ONE_MINUS_SRC_ALPHA
     TONEMAP_FS         the HDR framebuffer tone-mapped (x / (1 + x)) and sRGB-encoded */

#if defined(MESH_VS)
layout(location = 0) in vec3 pos;
layout(location = 1) in vec3 nrm;
/* mvp, then the model matrix's 3x3 part as columns with the albedo in their w */
layout(push_constant) uniform Mesh { mat4 mvp; vec4 n0, n1, n2; } pc;
layout(location = 0) out vec3 n_world;
layout(location = 1) out vec3 albedo;
void main()
{
    n_world = mat3(pc.n0.xyz, pc.n1.xyz, pc.n2.xyz) * nrm;
    albedo = vec3(pc.n0.w, pc.n1.w, pc.n2.w);
    gl_Position = pc.mvp * vec4(pos, 1.0);
}

#elif defined(MESH_FS)
/* the sun (the direction its light travels in, its radiance): the library's light, given by
   scene_vulkan.c as specialization constants */
layout(constant_id = 0) const float sun_x = 0.0;
layout(constant_id = 1) const float sun_y = -1.0;
layout(constant_id = 2) const float sun_z = 0.0;
layout(constant_id = 3) const float sun_r = 1.0;
layout(constant_id = 4) const float sun_g = 1.0;
layout(constant_id = 5) const float sun_b = 1.0;
layout(location = 0) in vec3 n_world;
layout(location = 1) in vec3 albedo;
layout(location = 0) out vec4 colour;
void main()
{
    float l = max(dot(normalize(n_world), -vec3(sun_x, sun_y, sun_z)), 0.0);
    colour = vec4(albedo / 3.14159265 * (vec3(sun_r, sun_g, sun_b) * l + vec3(0.8, 0.95, 1.25)), 1.0);
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
