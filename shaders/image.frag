#version 330 core
// The rendered image, or one of its per-pixel counters through the heat colour map.
in vec2 uv;
out vec4 fragColor;
uniform sampler2D colorTex;  // the image as 8-bit RGBA, as the PNG writer quantises it
uniform sampler2D heatTex;   // one counter per pixel
uniform int mode;            // 0: colour, 1: heat map, 2: heat map on a log scale
uniform float scale;         // counter value shown at the top of the colour map
uniform vec3 stops[8];       // colour map, evenly spaced (app/viewer/colormap.cpp)
uniform int stopCount;

vec3 colormap(float v) {
    float x = clamp(v, 0.0, 1.0) * float(stopCount - 1);
    int i = min(int(floor(x)), stopCount - 2);
    return mix(stops[i], stops[i + 1], x - float(i));
}

void main() {
    vec2 t = vec2(uv.x, 1.0 - uv.y);  // image row 0 is the top row
    if (mode == 0)
        fragColor = vec4(clamp(texture(colorTex, t).rgb, 0.0, 1.0), 1.0);
    else if (mode == 1)
        fragColor = vec4(colormap(texture(heatTex, t).r / scale), 1.0);
    else  // as heatValue() in app/viewer/colormap.cpp
        fragColor = vec4(colormap(log(1.0 + texture(heatTex, t).r) / log(1.0 + scale)), 1.0);
}
