#version 330 core
// The smaller image's texel under this pixel (the texture's own filter, nearest): cheaper on a CPU
// rasteriser than glBlitFramebuffer, which takes a generic path there, and than bilinear filtering.

in vec2 v_uv;
uniform sampler2D u_image;
out vec4 frag_color;

void main() {
    frag_color = vec4(texture(u_image, v_uv).rgb, 1.0);
}
