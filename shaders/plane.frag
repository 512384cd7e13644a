#version 330 core
// Two-sided planes: a checker of 1 m cells with anti-aliased grid lines, a bright rim along the edges
// of finite planes so they read from any side, and fog with distance (the infinite ground fades into
// the background). The front face (the side the normal points to) is opaque. The back face is a wall
// you look through (the near wall of a closed box seen from outside): the renderer draws it after the
// balls, blended, so it is a faint, darker tint with its grid and rim kept visible.

#include "common.glsl"

in vec3 v_world;
in vec2 v_local;
flat in vec2 v_half_size;
flat in vec3 v_normal;
flat in vec3 v_color;

out vec4 frag_color;

const float EDGE_WIDTH = 0.06;   // metres
const vec3 EDGE_COLOR = vec3(0.96, 0.96, 0.90);
const float BACK_ALPHA = 0.18;   // opacity of a back face's cells
const float BACK_GRID_ALPHA = 0.45;
const float BACK_EDGE_ALPHA = 0.9;

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

void main() {
    vec3 n = gl_FrontFacing ? v_normal : -v_normal;
    vec2 cell = floor(v_local);
    float checker = mod(cell.x + cell.y, 2.0);
    vec3 albedo = v_color * mix(0.90, 1.0, checker);
    float lines = grid(v_local, 1.0, 1.0);
    albedo = mix(albedo, albedo * 0.65, lines);
    if (!gl_FrontFacing) albedo *= 0.75;

    // edge band of finite planes
    vec2 inside = v_half_size - abs(v_local);
    float edge_distance = min(inside.x, inside.y);
    float aa = max(fwidth(edge_distance), 1e-6);
    float edge = 1.0 - smoothstep(EDGE_WIDTH - aa, EDGE_WIDTH + aa, edge_distance);
    albedo = mix(albedo, EDGE_COLOR, edge);

    float alpha = 1.0;
    if (!gl_FrontFacing) {
        alpha = mix(mix(BACK_ALPHA, BACK_GRID_ALPHA, lines), BACK_EDGE_ALPHA, edge);
    }

    vec3 color = shade(albedo, n, v_world, 24.0, 0.08);
    frag_color = vec4(fog(color, v_world), alpha);
}
