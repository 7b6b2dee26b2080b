// Dear ImGui's OpenGL3 renderer backend, compiled here to call GL directly (no loader): the
// copy in Debian's libimgui.a loads GL through gl3w, which fails under OSMesa. Linked ahead of
// libimgui.a, so the archive's copy is never pulled in.
#include "app/viewer/gl.h"
#define IMGUI_IMPL_OPENGL_LOADER_CUSTOM
#include LANCER_IMGUI_OPENGL3_SOURCE
