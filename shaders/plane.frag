#version 330 core
// Two-sided planes: a checker of 1 m cells with anti-aliased grid lines, a bright rim along the edges
// of finite planes so they read from any side, and fog with distance (the infinite ground fades into
// the background). The front face (the side the normal points to) is opaque. So is the back of a solid
// plane (a floor or a slope: renderer.py), lit as a face of its own (two-sided lighting: the normal
// turned towards the eye) in its own colour. The back of any other plane is a wall you look through
// (the near wall of a closed box seen from outside): the renderer draws it after the balls, blended, so
// it is a faint, darker tint with its grid and rim kept visible. The selected plane (clicked in the
// viewer) has a wide amber rim, or an amber tint if it is infinite and has no rim.
//
// The balls shade the opaque faces: each one near the ray towards the sun casts a soft-edged shadow,
// and each one close by hides part of the sky (contact darkening). The renderer bins the balls in a
// grid on a plane perpendicular to the sun (see shadows.py); a fragment reads only its own cell. The
// solid finite planes cast soft-edged shadows too (casters.glsl), so the ground under a slope is in its
// shade, and a ball's shadow falls on the first thing below it, not through the slope as well.

#include "common.glsl"
#include "casters.glsl"

in vec3 v_world;
in vec2 v_local;
in vec2 v_shadow_grid;                  // grid coordinates of v_world, from plane.vert
flat in vec2 v_half_size;
flat in vec3 v_normal;
flat in vec3 v_color;
flat in float v_selected;
flat in float v_solid;
flat in int v_index;
#if CASTER_GROUPS > 0
in vec4 v_caster_u[CASTER_GROUPS];      // where this point's ray meets the first casters (plane.vert)
in vec4 v_caster_v[CASTER_GROUPS];
in vec4 v_caster_t[CASTER_GROUPS];
#endif

uniform samplerBuffer u_shadow_balls;   // centre xyz, radius; grouped by cell, nearest the sun first
uniform isamplerBuffer u_shadow_cells;  // cell k's balls are rows [cells[k].x, cells[k].y)
uniform vec2 u_shadow_shape;            // cells along u and v; (0, 0): no shadows
uniform float u_shadow_reach;           // ball radii from the centre where a ball's shading ends
uniform float u_back_pass;              // back faces drawn now: 1 the solid ones, 0 the see-through ones

out vec4 frag_color;

const float EDGE_WIDTH = 0.06;   // metres
const vec3 EDGE_COLOR = vec3(0.96, 0.96, 0.90);
const float BACK_ALPHA = 0.18;   // opacity of a back face's cells
const float BACK_GRID_ALPHA = 0.45;
const float BACK_EDGE_ALPHA = 0.9;
const float SELECTED_EDGE_WIDTH = 0.16;   // metres
const vec3 SELECTED_COLOR = vec3(1.0, 0.72, 0.05);

// 1 where a grid line of the given spacing passes, 0 elsewhere, anti-aliased and faded out where the
// lines get denser than the pixels.
float grid(vec2 p, float spacing, float width_pixels) {
    vec2 g = p / spacing;
    vec2 w = fwidth(g);
    vec2 line = abs(fract(g - 0.5) - 0.5) / max(w, vec2(1e-6));
    float on = 1.0 - min(min(line.x, line.y) / width_pixels, 1.0);
    float density = max(w.x, w.y);
    return on * (1.0 - smoothstep(0.15, 0.5, density));
}


// The balls near this point's ray towards the sun: the fraction of the sun it sees (x) and the
// fraction of the ambient light the close ones leave (y). Its cell holds every ball that can shade it.
// A CPU rasteriser runs the code after a per-pixel branch anyway (masked), so this is kept short, and
// the grid coordinates come interpolated from the vertex shader.
vec2 ball_shading(vec3 p, vec3 n, vec2 g) {
    bool inside = all(greaterThanEqual(g, vec2(0.0))) && all(lessThan(g, u_shadow_shape));
    ivec2 c = ivec2(clamp(g, vec2(0.0), max(u_shadow_shape - 1.0, vec2(0.0))));
    ivec2 rows = inside ? texelFetch(u_shadow_cells, c.y * int(u_shadow_shape.x) + c.x).xy : ivec2(0);
    bool lit_side = dot(n, u_sun_direction) > 0.0;
    float sun = 1.0;
    float ambient = 1.0;
    for (int i = rows.x; i < rows.y; ++i) {
        vec4 ball = texelFetch(u_shadow_balls, i);
        float r = ball.w;
        vec3 d = ball.xyz - p;
        float l2 = dot(d, d);
        float t = dot(d, u_sun_direction);          // along the ray to the sun
        if (lit_side && t > 0.0) {
            float miss = sqrt(max(l2 - t * t, 0.0));  // how far the ray passes from the centre
            float w = min(t * SUN_RADIUS, (u_shadow_reach - 1.0) * r) + 1e-4;  // within reach
            sun = min(sun, smoothstep(-w, w, miss - r));
        }
        // the sky the ball hides, cosine weighted: (r/l)^2 cos(theta), all of it where it touches
        float l = sqrt(l2);
        float hidden = max(dot(n, d), 0.0) / l * r * r / l2;
        hidden *= 1.0 - smoothstep(0.6 * u_shadow_reach * r, u_shadow_reach * r, l);
        ambient *= 1.0 - min(hidden, 1.0);
    }
    return vec2(sun, ambient);
}

// The share of the sun this point sees past the casting planes: the first ones (up to eight) from the
// rays interpolated from the vertices, any after them worked out here (casters.glsl).
vec4 group_shades(vec4 along_u, vec4 along_v, vec4 t, int g) {
    vec4 half_u = vec4(u_caster_half[4 * g].x, u_caster_half[4 * g + 1].x, u_caster_half[4 * g + 2].x,
                       u_caster_half[4 * g + 3].x);
    vec4 half_v = vec4(u_caster_half[4 * g].y, u_caster_half[4 * g + 1].y, u_caster_half[4 * g + 2].y,
                       u_caster_half[4 * g + 3].y);
    return caster_shades(along_u, along_v, t, half_u, half_v);
}

float planes_shadow() {
    vec4 sun = vec4(1.0);
#if CASTER_GROUPS > 0
    sun = min(sun, group_shades(v_caster_u[0], v_caster_v[0], v_caster_t[0], 0));
#endif
#if CASTER_GROUPS > 1
    sun = min(sun, group_shades(v_caster_u[1], v_caster_v[1], v_caster_t[1], 1));
#endif
    float rest = 1.0;
#if CASTERS > 4 * CASTER_GROUPS
    rest = plane_shadow_from(v_world, v_index, 4 * CASTER_GROUPS);
#endif
    return min(min(min(sun.x, sun.y), min(sun.z, sun.w)), rest);
}

void main() {
    bool back = !gl_FrontFacing;
    if (back && (v_solid > 0.5) != (u_back_pass > 0.5)) discard;  // drawn in the other back pass
    bool see_through = back && v_solid < 0.5;
    vec3 n = gl_FrontFacing ? v_normal : -v_normal;
    vec2 cell = floor(v_local);
    float checker = mod(cell.x + cell.y, 2.0);
    vec3 albedo = v_color * mix(0.90, 1.0, checker);
    float lines = grid(v_local, 1.0, 1.0);
    albedo = mix(albedo, albedo * 0.65, lines);
    if (see_through) albedo *= 0.75;

    // edge band of finite planes
    vec2 inside = v_half_size - abs(v_local);
    float edge_distance = min(inside.x, inside.y);
    float aa = max(fwidth(edge_distance), 1e-6);
    float width = v_selected > 0.5 ? SELECTED_EDGE_WIDTH : EDGE_WIDTH;
    float edge = 1.0 - smoothstep(width - aa, width + aa, edge_distance);
    albedo = mix(albedo, v_selected > 0.5 ? SELECTED_COLOR : EDGE_COLOR, edge);
    if (v_selected > 0.5 && v_half_size.x > 1.0e5) albedo = mix(albedo, SELECTED_COLOR, 0.35);

    float alpha = 1.0;
    if (see_through) {
        alpha = mix(mix(BACK_ALPHA, BACK_GRID_ALPHA, lines), BACK_EDGE_ALPHA, edge);
    }

    vec2 shading = see_through ? vec2(1.0) : ball_shading(v_world, n, v_shadow_grid);
    if (!see_through && dot(n, u_sun_direction) > 0.0) shading.x = min(shading.x, planes_shadow());
    vec3 color = shade_lit(albedo, n, v_world, 24.0, 0.08, shading.x, shading.y);
    frag_color = vec4(fog(color, v_world), alpha);
}
