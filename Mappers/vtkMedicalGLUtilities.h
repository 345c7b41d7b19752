// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkMedicalGLUtilities.h
 * @brief Private OpenGL helpers shared by the Mappers classes (not installed,
 * not wrapped): error flags read directly (VTK's error-check macros are
 * compiled out in release builds) and RAII guards for the current context,
 * pixel-buffer bindings and framebuffer bindings, and an ivec3 uniform
 * setter.
 */
#ifndef vtkMedicalGLUtilities_h
#define vtkMedicalGLUtilities_h

#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkShaderProgram.h"
#include "vtk_glew.h"

#include <string>

namespace medical_gl
{
inline const char* GLErrorName(GLenum err)
{
  switch (err)
  {
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    default:
      return "unknown OpenGL error";
  }
}
// Fetch and clear the OpenGL error flags; empty when there was none. (VTK's
// own error macros are compiled out in release builds, so check directly.)
inline std::string TakeGLErrors()
{
  std::string errors;
  for (int n = 0; n < 16; ++n)
  {
    const GLenum err = glGetError();
    if (err == GL_NO_ERROR)
    {
      break;
    }
    errors += (errors.empty() ? "" : ", ");
    errors += GLErrorName(err);
  }
  return errors;
}
// Makes a window's context current and restores the previous one.
class ScopedContext
{
public:
  explicit ScopedContext(vtkOpenGLRenderWindow* win)
    : Window(win)
  {
    this->Window->PushContext();
  }
  ~ScopedContext() { this->Window->PopContext(); }
  ScopedContext(const ScopedContext&) = delete;
  ScopedContext& operator=(const ScopedContext&) = delete;

private:
  vtkOpenGLRenderWindow* Window;
};
// Restores the binding of a buffer target (GL_PIXEL_PACK_BUFFER, ...) and
// binds 0 meanwhile, so that pixel transfers use client memory.
class ScopedBufferUnbind
{
public:
  ScopedBufferUnbind(GLenum target, GLenum bindingQuery)
    : Target(target)
  {
    glGetIntegerv(bindingQuery, &this->Saved);
    if (this->Saved != 0)
    {
      glBindBuffer(this->Target, 0);
    }
  }
  ~ScopedBufferUnbind()
  {
    if (this->Saved != 0)
    {
      glBindBuffer(this->Target, static_cast<GLuint>(this->Saved));
    }
  }
  ScopedBufferUnbind(const ScopedBufferUnbind&) = delete;
  ScopedBufferUnbind& operator=(const ScopedBufferUnbind&) = delete;

private:
  GLenum Target;
  GLint Saved = 0;
};
// Saves the framebuffer bindings and draw/read buffers, restores them on exit.
class ScopedFramebufferBindings
{
public:
  explicit ScopedFramebufferBindings(vtkOpenGLFramebufferObject* fbo)
    : FBO(fbo)
  {
    this->FBO->SaveCurrentBindingsAndBuffers();
  }
  ~ScopedFramebufferBindings() { this->FBO->RestorePreviousBindingsAndBuffers(); }
  ScopedFramebufferBindings(const ScopedFramebufferBindings&) = delete;
  ScopedFramebufferBindings& operator=(const ScopedFramebufferBindings&) = delete;

private:
  vtkOpenGLFramebufferObject* FBO;
};

// vtkShaderProgram has no ivec3 setter: sets one on the bound program.
// False when the program has no such (active) uniform.
inline bool SetUniformIVec3(vtkShaderProgram* program, const char* name, const int v[3])
{
  const GLint location = program->FindUniform(name);
  if (location < 0)
  {
    return false;
  }
  glUniform3i(location, v[0], v[1], v[2]);
  return true;
}

} // namespace medical_gl

#endif
