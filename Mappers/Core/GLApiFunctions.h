// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file GLApiFunctions.h
 * @brief The function table of mediso::GLApi (private to the GPU core).
 *
 * Only the core's own sources include this: it brings in the Khronos
 * OpenGL ES 3.0 header for the types, enums and signatures (the subset the
 * core uses is the same in OpenGL 3.2 core), plus the few desktop-only enums
 * the core asks for on desktop contexts.
 */
#ifndef MedicalIsosurfaces_GLApiFunctions_h
#define MedicalIsosurfaces_GLApiFunctions_h

#include "GLApi.h"
#include "GLFunctionList.h"

#include <GLES3/gl3.h>

// Desktop OpenGL only (core profile 3.2): asked for on desktop contexts only.
#ifndef GL_PROGRAM_POINT_SIZE
#define GL_PROGRAM_POINT_SIZE 0x8642
#endif
#ifndef GL_POINT_SIZE_RANGE
#define GL_POINT_SIZE_RANGE 0x0B12
#endif
#ifndef GL_POINT_SIZE_GRANULARITY
#define GL_POINT_SIZE_GRANULARITY 0x0B13
#endif
#ifndef GL_CONTEXT_PROFILE_MASK
#define GL_CONTEXT_PROFILE_MASK 0x9126
#endif

namespace mediso
{

struct GLApi::Functions
{
#define MEDISO_GL_MEMBER(f) decltype(&::gl##f) f = nullptr;
  MEDISO_GL_FUNCTIONS(MEDISO_GL_MEMBER)
#undef MEDISO_GL_MEMBER
  // Desktop only (null on GL ES).
  void(GL_APIENTRYP BindFragDataLocation)(GLuint, GLuint, const GLchar*) = nullptr;
};

} // namespace mediso

#endif
