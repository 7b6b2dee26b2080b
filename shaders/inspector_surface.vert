#version 330 core
// A quad over the whole viewport (no vertex buffer: the corners come from gl_VertexID), for the
// inspector's traced surfaces.
out vec2 uv;
void main() {
    vec2 p = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
    uv = p;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
