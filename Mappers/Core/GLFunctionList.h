// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file GLFunctionList.h
 * @brief The OpenGL functions the GPU core calls, as X-macro lists (no GL header needed).
 *
 * The GPU core (HistoPyramidGL, IsosurfaceRendererGL) runs on OpenGL 3.2 core
 * and on OpenGL ES 3.0 / WebGL2, inside whatever loader its host uses: VTK's
 * GLEW in the ParaView plugin, EGL in mediso-render, Emscripten's static
 * WebGL2 bindings in the browser. It therefore never links a GL library: it
 * calls through a table of function pointers that the host fills from a
 * lookup by name (mediso::GLApi::Load()). These lists are the one place the
 * functions are named. A host that has the functions in scope (GLEW, or
 * GLES3/gl3.h with prototypes) can answer the lookup by expanding a list:
 *
 * @code
 * void* LookUp(const char* name, void*)
 * {
 * #define MEDISO_LOOK_UP(f) if (std::strcmp(name, "gl" #f) == 0) return reinterpret_cast<void*>(gl##f);
 *   MEDISO_GL_FUNCTIONS(MEDISO_LOOK_UP)
 *   return nullptr;
 * }
 * @endcode
 *
 * MEDISO_GL_FUNCTIONS: in both OpenGL 3.2 core and OpenGL ES 3.0, with the
 * same signatures; every one is required. MEDISO_GL_DESKTOP_FUNCTIONS: only
 * in desktop OpenGL; looked up, and used, on desktop contexts only.
 */
#ifndef MedicalIsosurfaces_GLFunctionList_h
#define MedicalIsosurfaces_GLFunctionList_h

// clang-format off
#define MEDISO_GL_FUNCTIONS(X)                                                                     \
  X(ActiveTexture) X(AttachShader) X(BindAttribLocation) X(BindBuffer) X(BindFramebuffer)          \
  X(BindRenderbuffer)                                                                              \
  X(BindSampler) X(BindTexture) X(BindVertexArray) X(BlendEquationSeparate)                         \
  X(BlendFuncSeparate) X(BufferData) X(CheckFramebufferStatus) X(ClearBufferfv)                     \
  X(ClearBufferuiv) X(ColorMask) X(CompileShader) X(CreateProgram) X(CreateShader)                  \
  X(DeleteBuffers) X(DeleteFramebuffers) X(DeleteProgram) X(DeleteRenderbuffers)                    \
  X(DeleteShader) X(DeleteTextures) X(DeleteVertexArrays) X(DepthFunc) X(DepthMask) X(Disable)      \
  X(DisableVertexAttribArray) X(DrawArrays) X(DrawArraysInstanced) X(DrawBuffers) X(DrawElements)   \
  X(Enable)                                                                                        \
  X(EnableVertexAttribArray) X(Finish) X(FramebufferRenderbuffer) X(FramebufferTexture2D)           \
  X(FramebufferTextureLayer) X(GenBuffers) X(GenFramebuffers) X(GenRenderbuffers)                   \
  X(GenTextures) X(GenVertexArrays) X(GetBooleanv) X(GetError) X(GetFloatv) X(GetIntegerv)          \
  X(GetProgramInfoLog) X(GetProgramiv) X(GetShaderInfoLog) X(GetShaderiv) X(GetString)              \
  X(GetStringi) X(GetUniformLocation) X(IsEnabled) X(LinkProgram) X(PixelStorei) X(ReadBuffer)      \
  X(ReadPixels) X(RenderbufferStorage) X(ShaderSource) X(TexImage2D) X(TexImage3D)                  \
  X(TexSubImage2D) X(TexSubImage3D)                                                               \
  X(TexParameteri) X(Uniform1f) X(Uniform1fv) X(Uniform1i) X(Uniform1iv) X(Uniform1uiv)            \
  X(Uniform2f) X(Uniform2i) X(Uniform3fv) X(Uniform3i) X(Uniform4f) X(Uniform4fv)                   \
  X(UniformMatrix3fv) X(UniformMatrix4fv) X(UseProgram) X(VertexAttribPointer) X(Viewport)

#define MEDISO_GL_DESKTOP_FUNCTIONS(X) X(BindFragDataLocation)
// clang-format on

#endif
