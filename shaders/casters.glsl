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

// The fraction of the sun point p sees past the casting planes (the plane ``self`` left out, -1 for
// none); the edge is soft over the sun's angular radius, as a ball's is.
float plane_shadow(vec3 p, int self) {
    float sun = 1.0;
    for (int i = 0; i < u_caster_count; ++i) {
        if (u_caster_index[i] == self) continue;
        vec3 normal = u_caster_normal[i];
        float facing = dot(u_sun_direction, normal);
        if (abs(facing) < 1e-4) continue;  // edge on to the sun: no shadow to speak of
        float t = dot(u_caster_center[i] - p, normal) / facing;
        if (t <= 1e-3) continue;  // the plane is not between p and the sun
        vec3 q = p + t * u_sun_direction - u_caster_center[i];
        vec2 outside = abs(vec2(dot(q, u_caster_u[i]), dot(q, u_caster_v[i]))) - u_caster_half[i];
        float w = t * SUN_RADIUS + 1e-3;
        sun = min(sun, smoothstep(-w, w, max(outside.x, outside.y)));
    }
    return sun;
}
