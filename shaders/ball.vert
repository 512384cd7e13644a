#version 330 core
// One camera-facing quad per ball (instanced); ball.frag ray-casts the exact sphere inside it.
// The quad is perpendicular to the eye→centre direction, on the sphere's nearest tangent plane, and
// just big enough to hold the sphere's silhouette cone there: half size (d−r)·r/√(d²−r²).

layout(location = 0) in vec2 a_corner;          // (±1, ±1), per vertex
layout(location = 1) in vec4 a_center_radius;   // per instance: centre xyz, radius
layout(location = 2) in vec4 a_orientation;     // per instance: unit quaternion (x, y, z, w)
layout(location = 3) in vec4 a_color;           // per instance: sRGB colour, alpha unused

uniform mat4 u_view_projection;
uniform vec3 u_eye;

out vec3 v_world;
flat out vec4 v_center_radius;
flat out vec4 v_orientation;
flat out vec3 v_color;

void main() {
    vec3 c = a_center_radius.xyz;
    float r = a_center_radius.w;
    vec3 to_center = c - u_eye;
    float d = length(to_center);
    v_center_radius = a_center_radius;
    v_orientation = a_orientation;
    v_color = a_color.rgb;
    if (d <= r * 1.001) {           // the eye is inside this ball: draw nothing
        v_world = c;
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
        return;
    }
    vec3 w = to_center / d;
    vec3 helper = abs(w.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 u = normalize(cross(w, helper));
    vec3 v = cross(u, w);
    // The quad sits on the tangent plane nearest the eye: every point of the sphere lies behind it
    // along any eye ray, so the fragment depth only ever moves away from the quad's (depth_greater),
    // which lets the depth test reject hidden balls before their fragments are shaded.
    float front = d - r;
    float half_size = front * r / sqrt(d * d - r * r) * 1.05;   // a little margin for edge anti-aliasing
    vec3 p = u_eye + w * front + (u * a_corner.x + v * a_corner.y) * half_size;
    v_world = p;
    gl_Position = u_view_projection * vec4(p, 1.0);
}
