// The OpenGL 3.3 core entry points the console calls. Linux's libGL (GLVND) exports every core
// function, so prototypes are enough and no loader library is needed; Dear ImGui's OpenGL backend
// keeps its own small loader for itself.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
