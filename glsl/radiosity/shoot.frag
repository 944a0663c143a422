#version 450 core
// One batch of shooters' energy into every element (Coombe and Harris 39.2.2):
// a pass over the element atlas (the chapter draws each receiving polygon
// orthographically at its texture's resolution; here each texel's position,
// normal and area come from textures made once). For shooter k (a sub-element
// of the chosen tile, or one hemisphere of a point light):
//   dB = rho * B_k * F(x -> outline_k) * V
// (`--form-factor polygon`: Lambert's exact point-to-polygon form factor to
// the sub-element's outline, which on a curved surface follows its edges
// along the surface; the disc's for the block's own elements, which a curved
// block lights), or
//   dB = rho * B_k * A_k * max(cos_r cos_k, 0) / (pi d^2 + A_k) * V
// (`disc`: the chapter's oriented-disc form factor), or for a point light of
// intensity I,
//   dB = rho * I * max(cos_r, 0) / d^2 * V,
// from the one of its six axis hemispheres whose axis is nearest the
// receiver's direction.
// V: the receiver's patch is what shooter k's item buffer holds in its
// direction, or a surface continuing the receiver's (`sees`), or, where
// nothing is there, a texel beside it does. dB is the shot's alone (accumulate.frag adds it, once the
// tiles it makes uneven are split and shot again at their children).
#include "common/sampling.glsl"
#include "radiosity/form_factor.glsl"

uniform sampler2D u_element_position; // xyz, w = area (0: no element)
uniform sampler2D u_element_normal;   // xyz, w = patch
uniform sampler2D u_element_albedo;   // rgb reflectance
uniform sampler2D u_shooters;         // a row a shooter: (pos, kind), (normal, area), (B or I, outline vertices),
                                      // then the outline's vertices (w of the first two:
                                      // the block's first texel in the atlas)
uniform int u_shooter_count;
uniform sampler2D u_item_buffers;     // shooter k's at tile (k % u_item_columns, k / u_item_columns)
uniform int u_item_size;
uniform int u_item_columns;
uniform int u_polygon;                // 1: the polygon form factor; 0: the disc's
uniform int u_block;                  // elements a shooter a side

// `sees`: the sine of the angle between h and a texel's plane below which
// the plane does not decide visibility; and how far behind a plane, over the
// receiver's distance, a receiver still counts as in it (float rounding).
const float GRAZING = 0.1;
const float COPLANAR = 1e-4;

layout(location = 0) out vec4 o_shot;

// The signed axis nearest direction d, as 1 + index (x, y, z), negative for
// the negative axis; ties go to the earlier axis.
int nearest_axis(vec3 d) {
    vec3 a = abs(d);
    int i = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    return d[i] >= 0.0 ? i + 1 : -(i + 1);
}

// The facet normal item_buffer.frag packs into (z, w).
vec3 item_normal(vec2 zw) {
    float s = zw.y >= 0.0 ? 1.0 : -1.0;
    float y = zw.y - 4.0 * s;
    return vec3(zw.x, y, s * sqrt(max(0.0, 1.0 - zw.x * zw.x - y * y)));
}

// How far the receiver at distance d in unit direction h from the shooter
// lies in front of (on the shooter's side of) an item-buffer texel's plane.
float in_front(vec4 item, vec3 h, float d) {
    return item.y + d * dot(h, item_normal(item.zw));
}

// Whether that receiver lies in the texel's plane, to float rounding.
bool in_plane(vec4 item, vec3 h, float d) {
    return abs(in_front(item, h, d)) <= COPLANAR * d;
}

// Whether an item-buffer texel lets a receiver (patch, normal n, size
// sqrt of its area, at distance d in unit direction h from the shooter) be
// seen, the texel's own ray running along hc:
// - it holds the receiver's own patch; or
// - a surface facing the way the receiver does, which the texel's ray
//   meets no nearer than `nearest` (the receiver's distance less its own
//   size and two texels' width), or whose plane holds the receiver: an edge
//   it shares with a coplanar neighbour (a mesh's next triangle), where the
//   chapter's IDs alone lose every element along the edge, and where, seen
//   edge-on, one texel spans depths far apart; or
// - a surface beside the receiver, which the texel's ray meets no farther
//   than the receiver's distance plus the slack, whose plane has the
//   receiver a quarter of its size or more on the shooter's side, h
//   crossing it at more than a grazing angle: an edge it shares with
//   another plane (a wall meeting the floor).
// The facing test keeps a closed surface's near side blocking its far
// side's inside at the silhouette, where the two are as near; a facet's
// plane has the rest of a convex surface behind it, but for its own bulge
// (the chord's sagitta), less than the margin; and a surface far behind a
// receiver at its silhouette (the floor past a ball) does not let in its
// inside.
bool sees(vec4 item, int patch_id, vec3 n, float size, vec3 h, vec3 hc, float d, float slack) {
    if (int(item.x) == patch_id) return true;
    if (item.x < -1.5) return false;
    vec3 m = item_normal(item.zw);
    float plane = item.y;                 // the shooter's distance from the texel's plane
    float along_texel = -dot(hc, m);      // > 0: the texel's ray runs into the plane's shown side
    // The texel's ray meets its surface at plane / along_texel.
    bool meets_past = along_texel <= 0.0 || plane >= (d - slack) * along_texel;
    if (dot(m, n) > 0.9 && (meets_past || in_plane(item, h, d))) return true;
    bool meets_beside = along_texel > 0.0 && plane <= (d + slack) * along_texel;
    return -dot(h, m) > GRAZING && meets_beside && in_front(item, h, d) >= 0.25 * size;
}

// The unit direction of the ray through texel `texel` (within its tile) of
// an item buffer whose shooter has frame (t, b, a).
vec3 texel_direction(ivec2 texel, vec3 t, vec3 b, vec3 a) {
    vec2 xy = (vec2(texel) + 0.5) / float(u_item_size) * 2.0 - 1.0;
    float r2 = dot(xy, xy);
    if (r2 > 1.0) {
        xy *= inversesqrt(r2);
        r2 = 1.0;
    }
    return normalize(t * xy.x + b * xy.y + a * sqrt(1.0 - r2));
}

// The texel of a shooter's item buffer holding hemisphere point xy.
ivec2 item_texel(vec2 xy) {
    vec2 uv = xy * 0.5 + 0.5;
    return clamp(ivec2(uv * float(u_item_size)), ivec2(0), ivec2(u_item_size - 1));
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 e = texelFetch(u_element_position, px, 0);
    o_shot = vec4(0.0);
    if (e.w <= 0.0) return;
    vec4 en = texelFetch(u_element_normal, px, 0);
    vec3 rho = texelFetch(u_element_albedo, px, 0).rgb;
    if (all(equal(rho, vec3(0.0)))) return;
    vec3 sum = vec3(0.0);
    for (int k = 0; k < u_shooter_count; ++k) {
        vec4 s0 = texelFetch(u_shooters, ivec2(0, k), 0);
        vec4 s1 = texelFetch(u_shooters, ivec2(1, k), 0);
        vec4 s2 = texelFetch(u_shooters, ivec2(2, k), 0);
        vec3 energy = s2.rgb;
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
        ivec2 texel = item_texel(xy);
        ivec2 at = tile + texel;
        float d = sqrt(d2);
        float size = sqrt(e.w);
        float slack = size + 4.0 * d / float(u_item_size);
        vec4 item = texelFetch(u_item_buffers, at, 0);
        bool visible = sees(item, int(en.w), en.xyz, size, h, texel_direction(texel, t, b, s1.xyz), d, slack);
        // Not seen there: the receiver may lie just past the texel that
        // holds its own flat patch, where the rasteriser's chords and texel
        // centres misplace the patch's edge (a mesh's edge seen edge-on) by
        // a texel. A texel beside it that holds the receiver's own patch, in
        // a plane through the receiver, decides (a curved patch's facets are
        // chords, off the receiver by their sagitta). Where nothing at all
        // is there (-2, the clear value: the receiver at its own surface's
        // silhouette, such as a disc's rim, or the texel at the projection's
        // rim, its centre outside the projected disc), a texel beside it
        // that lets the receiver be seen, within the same slack, decides:
        // at any depth, a surface far past it (the light beyond a ball's
        // silhouette, seen from the floor) would let in the ball's inside,
        // where the ray has passed between its chords and the true surface.
        // Either way, a closed surface's near side still blocks its far
        // side's inside: the two are different patches.
        bool nothing = item.x < -1.5;
        for (int n = 0; n < 4 && !visible; ++n) {
            ivec2 step = n < 2 ? ivec2(2 * n - 1, 0) : ivec2(0, 2 * n - 5);
            ivec2 q = clamp(at + step, tile, tile + ivec2(u_item_size - 1));
            vec4 beside = texelFetch(u_item_buffers, q, 0);
            visible = nothing
                ? sees(beside, int(en.w), en.xyz, size, h, texel_direction(q - tile, t, b, s1.xyz), d, slack)
                : int(beside.x) == int(en.w) && in_plane(beside, h, d);
        }
        if (!visible) continue;
        float f;
        if (s0.w != 0.0) {
            f = cos_r / d2;
        } else {
            f = cos_r * cos_s * s1.w / (PI * d2 + s1.w);
            if (u_polygon != 0 && s2.w >= 3.0) {
                vec3 outline[SHOOTER_OUTLINE];
                int count = min(int(s2.w), SHOOTER_OUTLINE);
                for (int v = 0; v < SHOOTER_OUTLINE; ++v) {
                    outline[v] = texelFetch(u_shooters, ivec2(3 + v, k), 0).xyz;
                }
                // A curved block's own elements lie on the surface its
                // outline bounds: for them the disc stands.
                ivec2 own = ivec2(texelFetch(u_shooters, ivec2(3, k), 0).w,
                                  texelFetch(u_shooters, ivec2(4, k), 0).w);
                if (any(lessThan(px, own)) || any(greaterThanEqual(px, own + u_block))) {
                    f = polygon_form_factor(e.xyz, en.xyz, outline, count);
                }
            }
        }
        sum += energy * f;
    }
    o_shot = vec4(rho * sum, 0.0);
}
