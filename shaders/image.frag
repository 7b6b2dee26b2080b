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
uniform sampler2D overlayTex;  // the overlays' layer, premultiplied RGBA, framebuffer rows
uniform int hasOverlay;

vec3 colormap(float v) {
    float x = clamp(v, 0.0, 1.0) * float(stopCount - 1);
    int i = min(int(floor(x)), stopCount - 2);
    return mix(stops[i], stops[i + 1], x - float(i));
}

void main() {
    vec2 t = vec2(uv.x, 1.0 - uv.y);  // image row 0 is the top row
    vec3 c;
    if (mode == 0)
        c = clamp(texture(colorTex, t).rgb, 0.0, 1.0);
    else if (mode == 1)
        c = colormap(texture(heatTex, t).r / scale);
    else  // as heatValue() in app/viewer/colormap.cpp
        c = colormap(log(1.0 + texture(heatTex, t).r) / log(1.0 + scale));
    if (hasOverlay != 0) {
        // Drawn like the framebuffer (row 0 at the bottom), as this FBO is.
        vec4 o = texture(overlayTex, uv);
        c = c * (1.0 - o.a) + o.rgb;
    }
    fragColor = vec4(c, 1.0);
}
