#version 330 core
// Planes as quads. Each vertex carries its plane-local coordinates (metres from the centre along the
// plane's width and depth axes) for the grid, the plane's half extents for the edge band, its normal
// its colour (bounciness) and whether it is solid from behind (a floor or slope, see renderer.py). Each
// plane is 6 consecutive vertices, so gl_VertexID / 6 is its index; the selected one (u_selected, -1 for
// none) is flagged for a highlighted rim. Where each vertex's ray towards the sun meets the first
// casting planes (casters.glsl) is worked out here and interpolated.

#include "common.glsl"
#include "casters.glsl"

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec2 a_local;
layout(location = 2) in vec2 a_half_size;   // a very large value for an infinite plane
layout(location = 3) in vec3 a_normal;
layout(location = 4) in vec3 a_color;
layout(location = 5) in float a_solid;      // 1: opaque from both sides; 0: see-through from behind

uniform mat4 u_view_projection;
uniform vec3 u_shadow_axis_u;           // the sun's grid (see plane.frag)
uniform vec3 u_shadow_axis_v;
uniform vec2 u_shadow_origin;
uniform float u_shadow_inverse_cell;
uniform float u_selected;

out vec3 v_world;
out vec2 v_local;
flat out vec2 v_half_size;
flat out vec3 v_normal;
flat out vec3 v_color;
out vec2 v_shadow_grid;  // the position's grid coordinates: affine, so interpolating them is exact
flat out float v_selected;
flat out float v_solid;
flat out int v_index;
#if CASTER_GROUPS > 0
out vec4 v_caster_u[CASTER_GROUPS];  // casters 4g..4g+3: where the ray meets each (u, v) and after how far (t)
out vec4 v_caster_v[CASTER_GROUPS];
out vec4 v_caster_t[CASTER_GROUPS];
#endif

void main() {
    v_world = a_position;
    v_shadow_grid = (vec2(dot(a_position, u_shadow_axis_u), dot(a_position, u_shadow_axis_v)) - u_shadow_origin)
                    * u_shadow_inverse_cell;
    v_local = a_local;
    v_half_size = a_half_size;
    v_normal = a_normal;
    v_color = a_color;
    v_selected = abs(float(gl_VertexID / 6) - u_selected) < 0.5 ? 1.0 : 0.0;
    v_solid = a_solid;
    v_index = gl_VertexID / 6;
#if CASTER_GROUPS > 0
    for (int g = 0; g < CASTER_GROUPS; ++g) {
        vec3 r0 = caster_ray(a_position, v_index, 4 * g);
        vec3 r1 = caster_ray(a_position, v_index, 4 * g + 1);
        vec3 r2 = caster_ray(a_position, v_index, 4 * g + 2);
        vec3 r3 = caster_ray(a_position, v_index, 4 * g + 3);
        v_caster_u[g] = vec4(r0.x, r1.x, r2.x, r3.x);
        v_caster_v[g] = vec4(r0.y, r1.y, r2.y, r3.y);
        v_caster_t[g] = vec4(r0.z, r1.z, r2.z, r3.z);
    }
#endif
    gl_Position = u_view_projection * vec4(a_position, 1.0);
}
