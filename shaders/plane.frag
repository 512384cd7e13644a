#version 330 core
// Two-sided planes: a checker of 1 m cells with anti-aliased grid lines, a bright rim along the edges
// of finite planes so they read from any side, and fog with distance (the infinite ground fades into
// the background). The front face (the side the normal points to) is opaque. The back face is a wall
// you look through (the near wall of a closed box seen from outside): the renderer draws it after the
// balls, blended, so it is a faint, darker tint with its grid and rim kept visible. The selected plane
// (clicked in the viewer) has a wide amber rim, or an amber tint if it is infinite and has no rim.

#include "common.glsl"

in vec3 v_world;
in vec2 v_local;
flat in vec2 v_half_size;
flat in vec3 v_normal;
flat in vec3 v_color;
flat in float v_selected;

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
    float width = v_selected > 0.5 ? SELECTED_EDGE_WIDTH : EDGE_WIDTH;
    float edge = 1.0 - smoothstep(width - aa, width + aa, edge_distance);
    albedo = mix(albedo, v_selected > 0.5 ? SELECTED_COLOR : EDGE_COLOR, edge);
    if (v_selected > 0.5 && v_half_size.x > 1.0e5) albedo = mix(albedo, SELECTED_COLOR, 0.35);

    float alpha = 1.0;
    if (!gl_FrontFacing) {
        alpha = mix(mix(BACK_ALPHA, BACK_GRID_ALPHA, lines), BACK_EDGE_ALPHA, edge);
    }

    vec3 color = shade(albedo, n, v_world, 24.0, 0.08);
    frag_color = vec4(fog(color, v_world), alpha);
}
