// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkMedicalGLUtilities.h
 * @brief Private OpenGL helper shared by the Mappers classes (not installed,
 * not wrapped): the RAII guard that makes a window's context current. Every
 * other GL object and state guard lives in the GPU core (Mappers/Core).
 */
#ifndef vtkMedicalGLUtilities_h
#define vtkMedicalGLUtilities_h

#include "vtkOpenGLRenderWindow.h"

namespace medical_gl
{
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
} // namespace medical_gl

#endif
