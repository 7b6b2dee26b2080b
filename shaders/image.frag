#version 330 core
// One of the image's per-pixel counters through the heat colour map (the colour image is
// composited on the CPU: app/viewer/image_view.cpp).
in vec2 uv;
out vec4 fragColor;
uniform sampler2D heatTex;   // one counter per pixel
// 0: heat map, 1: heat map on a log scale, 2: a signed difference (old - new) on the diverging
// map, 3: the same on a log scale
uniform int mode;
uniform float scale;         // counter value shown at the top of the colour map
uniform vec3 stops[8];       // colour map, evenly spaced (app/viewer/colormap.cpp)
uniform int stopCount;
uniform vec3 divStops[9];  // the diverging map, evenly spaced over [-1, 1]
uniform sampler2D overlayTex;  // the overlays' layer, premultiplied RGBA, framebuffer rows
uniform int hasOverlay;

vec3 colormap(float v) {
    float x = clamp(v, 0.0, 1.0) * float(stopCount - 1);
    int i = min(int(floor(x)), stopCount - 2);
    return mix(stops[i], stops[i + 1], x - float(i));
}

vec3 diverging(float v) {
    float x = (clamp(v, -1.0, 1.0) + 1.0) * 4.0;
    int i = min(int(floor(x)), 7);
    return mix(divStops[i], divStops[i + 1], x - float(i));
}

void main() {
    vec2 t = vec2(uv.x, 1.0 - uv.y);  // image row 0 is the top row
    vec3 c;
    if (mode == 0)
        c = colormap(texture(heatTex, t).r / scale);
    else if (mode == 1)  // as heatValue() in app/viewer/colormap.cpp
        c = colormap(log(1.0 + texture(heatTex, t).r) / log(1.0 + scale));
    else {
        float d = texture(heatTex, t).r;
        if (d >= 1e30) {  // kNoDiff (colormap.h), not NaN: drivers may fold isnan away
            // A pixel with nothing to compare yet: grey stripes, unlike any value of the map.
            float band = mod(floor((gl_FragCoord.x + gl_FragCoord.y) / 6.0), 2.0);
            c = vec3(0.16 + 0.08 * band);
        } else if (mode == 2) {  // as diffValue() in app/viewer/colormap.cpp
            c = diverging(d / scale);
        } else {
            c = diverging(sign(d) * log(1.0 + abs(d)) / log(1.0 + scale));
        }
    }
    if (hasOverlay != 0) {
        // Drawn like the framebuffer (row 0 at the bottom), as this FBO is.
        vec4 o = texture(overlayTex, uv);
        c = c * (1.0 - o.a) + o.rgb;
    }
    fragColor = vec4(c, 1.0);
}
