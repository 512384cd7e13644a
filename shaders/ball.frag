#version 330 core
// Ray-cast sphere impostor: exact silhouette, per-pixel normal and depth. The beach-ball pattern
// (six segments around the ball's own y axis, white caps at its poles) is read in the ball's body
// frame, so it turns with the orientation quaternion.

#extension GL_ARB_conservative_depth : enable
#include "common.glsl"
#include "casters.glsl"

#ifdef GL_ARB_conservative_depth
layout(depth_greater) out float gl_FragDepth;   // see ball.vert: the sphere is behind its quad
#endif

in vec3 v_world;
flat in vec4 v_center_radius;
flat in vec4 v_orientation;
flat in vec3 v_color;

uniform mat4 u_view_projection;
uniform float u_multisample;   // 1: edge coverage goes to alpha-to-coverage; 0: a hard edge at r
uniform float u_alpha;         // 1 for balls; below 1 for translucent ghosts (blended, coverage in alpha)

out vec4 frag_color;

const float SEGMENTS = 6.0;
const float CAP = 0.94;               // |y| of the body-frame normal above which the pole cap starts
const vec3 WHITE = vec3(0.95, 0.95, 0.92);
const float PI = 3.14159265358979;

// Rotate v by the inverse of unit quaternion q = (x, y, z, w): world frame → body frame.
vec3 rotate_inverse(vec4 q, vec3 v) {
    vec3 u = -q.xyz;
    vec3 t = 2.0 * cross(u, v);
    return v + q.w * t + cross(u, t);
}

void main() {
    vec3 c = v_center_radius.xyz;
    float r = v_center_radius.w;
    vec3 ray = normalize(v_world - u_eye);
    vec3 oc = u_eye - c;
    float b = dot(oc, ray);
    vec3 closest = oc - b * ray;                 // centre → closest point of the ray
    float miss = length(closest);                // distance of the ray from the centre
    float aa = max(fwidth(miss), 1e-6);
    // coverage of this pixel by the silhouette (for alpha-to-coverage when multisampling)
    float coverage = clamp((r - miss) / aa + 0.5, 0.0, 1.0);
    if (u_multisample > 0.5 ? coverage <= 0.0 : miss > r) discard;
    float h = sqrt(max(r * r - miss * miss, 0.0));
    float t = -b - h;
    vec3 hit = u_eye + ray * t;
    vec3 n = normalize(hit - c);

    // One written depth serves every sample of the pixel, while a wall just in front of the ball has
    // its own depth at each sample. The sphere's depth at the pixel centre would let the samples where
    // the wall is a little farther away show the ball through it (coloured dots where balls rest
    // against a wall). So write a depth the sphere does not come in front of anywhere in the pixel:
    // the centre plus its screen-space slope, half a pixel each way, and as much again because the
    // slope is a finite difference over a 2x2 block and underestimates a curved surface. The sphere
    // only ever moves back, by about a pixel's worth of depth, so depth_greater still holds.
    vec4 clip = u_view_projection * vec4(hit, 1.0);
    float depth = 0.5 * clip.z / clip.w + 0.5;
    gl_FragDepth = clamp(depth + fwidth(depth), 0.0, 1.0);

    vec3 body = rotate_inverse(v_orientation, n);
    float ring = length(body.xz);
    float s = (atan(body.z, body.x) / (2.0 * PI) + 0.5) * SEGMENTS;
    // anti-alias the segment borders with the analytic derivative of s (atan has a cut at ±π)
    float ds = length(fwidth(body.xz)) * SEGMENTS / (2.0 * PI * max(ring, 1e-3));
    float edge = min(fract(s), 1.0 - fract(s));
    float parity = mod(floor(s), 2.0);
    float blend = smoothstep(0.0, max(ds, 1e-4), edge);
    float white_amount = mix(0.5, parity, blend);
    float cap = smoothstep(CAP - 0.01, CAP + 0.01, abs(body.y));
    white_amount = max(white_amount, cap);
    vec3 albedo = mix(v_color, WHITE, white_amount);

    float sun = dot(n, u_sun_direction) > 0.0 ? plane_shadow(hit, -1) : 1.0;  // under a slope: its shade
    vec3 color = fog(shade_lit(albedo, n, hit, 48.0, 0.35, sun, 1.0), hit);
    frag_color = vec4(color, (u_multisample > 0.5 ? coverage : 1.0) * u_alpha);
}
