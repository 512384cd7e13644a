#version 330 core
// Bilinear sample of the smaller image (the texture's own filter): cheaper on a CPU rasteriser than
// glBlitFramebuffer, which takes a generic path there.

in vec2 v_uv;
uniform sampler2D u_image;
out vec4 frag_color;

void main() {
    frag_color = vec4(texture(u_image, v_uv).rgb, 1.0);
}
