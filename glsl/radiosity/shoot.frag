#version 450 core
// One batch of shooters' energy into every element (Coombe and Harris 39.2.2):
// a pass over the element atlas (the chapter draws each receiving polygon
// orthographically at its texture's resolution; here each texel's position,
// normal and area come from textures made once). For shooter k (a sub-element
// of the chosen patch, or one hemisphere of a point light):
//   dB = rho * B_k * A_k * max(cos_r cos_k, 0) / (pi d^2 + A_k) * V
// (the oriented-disc form factor), or for a point light of intensity I,
//   dB = rho * I * max(cos_r, 0) / d^2 * V,
// from the one of its six axis hemispheres whose axis is nearest the
// receiver's direction.
// V: the receiver's patch is what shooter k's item buffer holds in its
// direction. dB is added (blending) to the radiosity and the residual, and,
// when the shooters are lights, to the direct part too.
#include "common/sampling.glsl"

uniform sampler2D u_element_position; // xyz, w = area (0: no element)
uniform sampler2D u_element_normal;   // xyz, w = patch
uniform sampler2D u_element_albedo;   // rgb reflectance
uniform sampler2D u_shooters;         // 3 texels a shooter: (pos, kind), (normal, area), (B or I, 0)
uniform int u_shooter_count;
uniform sampler2D u_item_buffers;     // shooter k's at tile (k % u_item_columns, k / u_item_columns)
uniform int u_item_size;
uniform int u_item_columns;
uniform int u_lights;                 // 1: these shooters are lights (direct light)

layout(location = 0) out vec4 o_radiosity;

// The signed axis nearest direction d, as 1 + index (x, y, z), negative for
// the negative axis; ties go to the earlier axis.
int nearest_axis(vec3 d) {
    vec3 a = abs(d);
    int i = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    return d[i] >= 0.0 ? i + 1 : -(i + 1);
}

// The texel of a shooter's item buffer holding hemisphere point xy.
ivec2 item_texel(vec2 xy) {
    vec2 uv = xy * 0.5 + 0.5;
    return clamp(ivec2(uv * float(u_item_size)), ivec2(0), ivec2(u_item_size - 1));
}
layout(location = 1) out vec4 o_residual;
layout(location = 2) out vec4 o_direct;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 e = texelFetch(u_element_position, px, 0);
    o_radiosity = vec4(0.0);
    o_residual = vec4(0.0);
    o_direct = vec4(0.0);
    if (e.w <= 0.0) return;
    vec4 en = texelFetch(u_element_normal, px, 0);
    vec3 rho = texelFetch(u_element_albedo, px, 0).rgb;
    if (all(equal(rho, vec3(0.0)))) return;
    vec3 sum = vec3(0.0);
    for (int k = 0; k < u_shooter_count; ++k) {
        vec4 s0 = texelFetch(u_shooters, ivec2(0, k), 0);
        vec4 s1 = texelFetch(u_shooters, ivec2(1, k), 0);
        vec3 energy = texelFetch(u_shooters, ivec2(2, k), 0).rgb;
        vec3 r = s0.xyz - e.xyz;
        float d2 = dot(r, r);
        if (!(d2 > 0.0)) continue;
        r *= inversesqrt(d2);
        float cos_r = dot(en.xyz, r);
        float cos_s = -dot(s1.xyz, r);
        if (cos_r <= 0.0 || cos_s <= 0.0) continue;
        if (s0.w != 0.0 && nearest_axis(-r) != nearest_axis(s1.xyz)) continue; // another hemisphere's
        // Visibility: the item buffer in the receiver's direction from k.
        vec3 t, b;
        basis_around(s1.xyz, t, b);
        vec3 h = -r;
        vec2 xy = vec2(dot(h, t), dot(h, b));
        ivec2 tile = ivec2(k % u_item_columns, k / u_item_columns) * u_item_size;
        float id = texelFetch(u_item_buffers, tile + item_texel(xy), 0).x;
        // No fragment at all (-2, not a blocker's -1): a rim texel, whose
        // centre lies outside the projected disc though the receiver's
        // direction is inside. The texel one step in holds what is there.
        if (id < -1.5 && dot(xy, xy) > 0.0) {
            id = texelFetch(u_item_buffers, tile + item_texel(xy - normalize(xy) * 2.0 / float(u_item_size)), 0).x;
        }
        if (int(id) != int(en.w)) continue;
        float f = s0.w == 0.0 ? cos_r * cos_s * s1.w / (PI * d2 + s1.w)
                              : cos_r / d2;
        sum += energy * f;
    }
    vec3 db = rho * sum;
    o_radiosity = vec4(db, 0.0);
    o_residual = vec4(db, 0.0);
    o_direct = u_lights != 0 ? vec4(db, 0.0) : vec4(0.0);
}
