// Shadows cast by the solid finite planes (floors and slopes, renderer.py), on the other planes and on
// the balls: the renderer passes up to MAX_CASTERS of them as uniforms, and a point is shaded where its
// ray towards the sun crosses one inside its rectangle. Needs common.glsl (u_sun_direction) first.

const float SUN_RADIUS = 0.035;        // radians: a disc a little wider than the real sun, soft edges
const int MAX_CASTERS = 16;            // renderer.MAX_CASTERS
uniform int u_caster_count;
uniform vec3 u_caster_center[MAX_CASTERS];
uniform vec3 u_caster_u[MAX_CASTERS];  // unit axes in the plane
uniform vec3 u_caster_v[MAX_CASTERS];
uniform vec2 u_caster_half[MAX_CASTERS];
uniform vec3 u_caster_normal[MAX_CASTERS];
uniform int u_caster_index[MAX_CASTERS];  // the plane's index, so a plane does not shade itself

#ifndef CASTERS
#define CASTERS MAX_CASTERS  // renderer.py compiles each program for the count it has
#endif

// Where point p's ray towards the sun meets caster k's plane: (along its u axis, along its v axis,
// distance t from p), all affine in p; t is -1 where the caster shades nothing: it is p's own plane
// (``self``), edge on to the sun, or beyond the count set (shadows switched off).
vec3 caster_ray(vec3 p, int self, int k) {
    vec3 normal = u_caster_normal[k];
    float facing = dot(u_sun_direction, normal);
    float t = dot(u_caster_center[k] - p, normal) / facing;
    vec3 q = p + t * u_sun_direction - u_caster_center[k];
    bool casts = k < u_caster_count && u_caster_index[k] != self && abs(facing) >= 1e-4;
    return casts ? vec3(dot(q, u_caster_u[k]), dot(q, u_caster_v[k]), t) : vec3(0.0, 0.0, -1.0);
}

// The share of the sun seen past a caster whose rectangle the ray meets at ``along`` (its half
// extents ``half_size``) after ``t``: 1 unless the caster is between the point and the sun (t > 0),
// with the edge soft over the sun's angular radius, as a ball's is. Component-wise for four casters.
vec4 caster_shades(vec4 along_u, vec4 along_v, vec4 t, vec4 half_u, vec4 half_v) {
    vec4 outside = max(abs(along_u) - half_u, abs(along_v) - half_v);
    vec4 w = t * SUN_RADIUS + 1e-3;
    return mix(vec4(1.0), smoothstep(-w, w, outside), greaterThan(t, vec4(1e-3)));
}

float caster_shade(vec3 p, int self, int k) {
    vec3 ray = caster_ray(p, self, k);
    vec2 half_size = u_caster_half[k];
    return caster_shades(vec4(ray.x), vec4(ray.y), vec4(ray.z), vec4(half_size.x), vec4(half_size.y)).x;
}

// The fraction of the sun point p sees past the casting planes (the plane ``self`` left out, -1 for
// none). Written out once per caster, with constant indices, up to the CASTERS the program was compiled
// for: a CPU rasteriser (llvmpipe) reads a uniform array at a loop's index lane by lane, a gather per
// component, and runs both sides of every branch, so a loop over the casters cost more than the rest
// of the plane's shading together.
#define CAST(k) if (k >= first && k < CASTERS) sun = min(sun, caster_shade(p, self, k));
float plane_shadow_from(vec3 p, int self, int first) {
    float sun = 1.0;
    CAST(0) CAST(1) CAST(2) CAST(3) CAST(4) CAST(5) CAST(6) CAST(7)
    CAST(8) CAST(9) CAST(10) CAST(11) CAST(12) CAST(13) CAST(14) CAST(15)
    return sun;
}

float plane_shadow(vec3 p, int self) { return plane_shadow_from(p, self, 0); }

// The planes meet their first casters' rays per vertex, not per pixel: the ray's coordinates are affine
// in the point, so the rasteriser's interpolation gives each pixel the same values (to rounding), and
// a pixel only compares them with the rectangles. On llvmpipe that took the slopes' view from 8.2 to
// 6.4 ms a frame (four casters, 640x360). Four casters to a group of three vec4 varyings; two groups at
// most (24 components, well inside GL 3.3's 60); the casters after them are worked out per pixel.
#ifndef CASTER_GROUPS
#if CASTERS > 4
#define CASTER_GROUPS 2
#elif CASTERS > 0
#define CASTER_GROUPS 1
#else
#define CASTER_GROUPS 0
#endif
#endif
