#version 330 core
// Lines and filled triangles of a gl/batch.h Batch: a position and an 8-bit RGBA colour per
// vertex, taken to clip space by one matrix (world to clip, or image pixels to clip).
layout(location = 0) in vec3 position;
layout(location = 1) in vec4 color;
uniform mat4 toClip;
out vec4 vColor;
void main() {
    vColor = color;
    gl_Position = toClip * vec4(position, 1.0);
}
