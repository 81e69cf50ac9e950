// OpenGL 4.5 core declarations for the render module's .cpp files only (never include
// this from a public header). Functions come from GLVND's libOpenGL, which dispatches to
// the context EGL made current.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>
