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

// The share of the sun point p sees past caster k, 1 if it is p's own plane (``self``), is edge on to
// the sun, is not between p and the sun, or is beyond the count set (shadows switched off); the edge is
// soft over the sun's angular radius, as a ball's is.
float caster_shade(vec3 p, int self, int k) {
    vec3 normal = u_caster_normal[k];
    float facing = dot(u_sun_direction, normal);
    float t = dot(u_caster_center[k] - p, normal) / facing;
    vec3 q = p + t * u_sun_direction - u_caster_center[k];
    vec2 outside = abs(vec2(dot(q, u_caster_u[k]), dot(q, u_caster_v[k]))) - u_caster_half[k];
    float w = t * SUN_RADIUS + 1e-3;
    float shade = smoothstep(-w, w, max(outside.x, outside.y));
    bool casts = k < u_caster_count && u_caster_index[k] != self && abs(facing) >= 1e-4 && t > 1e-3;
    return casts ? shade : 1.0;
}

// The fraction of the sun point p sees past the casting planes (the plane ``self`` left out, -1 for
// none). Written out once per caster, with constant indices, up to the CASTERS the program was compiled
// for: a CPU rasteriser (llvmpipe) reads a uniform array at a loop's index lane by lane, a gather per
// component, and runs both sides of every branch, so a loop over the casters cost more than the rest
// of the plane's shading together.
#define CAST(k) if (k < CASTERS) sun = min(sun, caster_shade(p, self, k));
float plane_shadow(vec3 p, int self) {
    float sun = 1.0;
    CAST(0) CAST(1) CAST(2) CAST(3) CAST(4) CAST(5) CAST(6) CAST(7)
    CAST(8) CAST(9) CAST(10) CAST(11) CAST(12) CAST(13) CAST(14) CAST(15)
    return sun;
}
