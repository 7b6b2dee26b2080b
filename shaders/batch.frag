#version 330 core
// The vertex colour, its alpha scaled by the draw's opacity (a slider needs no re-upload).
in vec4 vColor;
out vec4 fragColor;
uniform float opacity;
void main() {
    fragColor = vec4(vColor.rgb, vColor.a * opacity);
}
