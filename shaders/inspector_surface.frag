#version 330 core
// The scene traced from the inspector's camera: its colour, and its depth written as the line
// pass's projection writes depth (glm::perspective or glm::ortho between nearDepth and
// farDepth), so lines behind a surface fail the depth test. depthTex holds the depth along the
// camera's forward axis, negative where the ray missed.
in vec2 uv;
out vec4 fragColor;
uniform sampler2D colorTex;
uniform sampler2D depthTex;
uniform int ortho;
uniform float nearDepth;
uniform float farDepth;
void main() {
    fragColor = vec4(texture(colorTex, uv).rgb, 1.0);
    float d = texture(depthTex, uv).r;
    if (d < 0.0) {
        gl_FragDepth = 1.0;
        return;
    }
    // A hair behind the surface: the edges of boxes that touch it stay visible.
    d *= 1.002;
    float n = nearDepth, f = farDepth;
    float ndc = ortho == 1 ? (2.0 * d - f - n) / (f - n)
                           : (f + n) / (f - n) - 2.0 * f * n / ((f - n) * d);
    gl_FragDepth = clamp(0.5 * (ndc + 1.0), 0.0, 1.0);
}
