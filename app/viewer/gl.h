// OpenGL 3.3 core entry points, called directly (GL_GLEXT_PROTOTYPES): the viewer binary links
// libGL, the headless test links libOSMesa, and no loader stands between them.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>
