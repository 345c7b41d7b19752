// SPDX-License-Identifier: BSD-3-Clause
#include "vtkOpenGLHistoPyramid.h"

#include "vtkMedicalGLUtilities.h"
#include "vtkDataArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderUtilities.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkType.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include "vtkHistoPyramidBase_fs.h"
#include "vtkHistoPyramidReduce_fs.h"

#include <array>
#include <cfloat>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

vtkStandardNewMacro(vtkOpenGLHistoPyramid);

namespace
{
using namespace medical_gl;
// How the base pass compares values: the GLSL value type of the volume.
enum class ValueKind
{
  Signed,   // isampler3D, int
  Unsigned, // usampler3D, uint
  Float     // sampler3D, float
};

// The texture format of a VTK scalar type, and the range of its values.
struct VolumeFormat
{
  GLenum InternalFormat = 0;
  GLenum Format = 0;
  GLenum DataType = 0;
  int UploadVTKType = 0; // type of the array handed to vtkTextureObject
  int BytesPerTexel = 0;
  ValueKind Kind = ValueKind::Float;
  double Min = 0.0; // value range of integer types
  double Max = 0.0;
};

template <typename T>
VolumeFormat IntegerFormat(GLenum internalFormat, GLenum dataType, int uploadType)
{
  VolumeFormat f;
  f.InternalFormat = internalFormat;
  f.Format = GL_RED_INTEGER;
  f.DataType = dataType;
  f.UploadVTKType = uploadType;
  f.BytesPerTexel = static_cast<int>(sizeof(T));
  f.Kind = std::numeric_limits<T>::is_signed ? ValueKind::Signed : ValueKind::Unsigned;
  f.Min = static_cast<double>(std::numeric_limits<T>::lowest());
  f.Max = static_cast<double>(std::numeric_limits<T>::max());
  return f;
}

bool ChooseFormat(int vtkType, VolumeFormat& f)
{
  switch (vtkType)
  {
    case VTK_CHAR:
      // Plain char is signed or unsigned depending on the platform.
      f = std::numeric_limits<char>::is_signed
        ? IntegerFormat<signed char>(GL_R8I, GL_BYTE, VTK_SIGNED_CHAR)
        : IntegerFormat<unsigned char>(GL_R8UI, GL_UNSIGNED_BYTE, VTK_UNSIGNED_CHAR);
      return true;
    case VTK_SIGNED_CHAR:
      f = IntegerFormat<signed char>(GL_R8I, GL_BYTE, VTK_SIGNED_CHAR);
      return true;
    case VTK_UNSIGNED_CHAR:
      f = IntegerFormat<unsigned char>(GL_R8UI, GL_UNSIGNED_BYTE, VTK_UNSIGNED_CHAR);
      return true;
    case VTK_SHORT:
      f = IntegerFormat<short>(GL_R16I, GL_SHORT, VTK_SHORT);
      return true;
    case VTK_UNSIGNED_SHORT:
      f = IntegerFormat<unsigned short>(GL_R16UI, GL_UNSIGNED_SHORT, VTK_UNSIGNED_SHORT);
      return true;
    case VTK_INT:
      f = IntegerFormat<int>(GL_R32I, GL_INT, VTK_INT);
      return true;
    case VTK_UNSIGNED_INT:
      f = IntegerFormat<unsigned int>(GL_R32UI, GL_UNSIGNED_INT, VTK_UNSIGNED_INT);
      return true;
    case VTK_FLOAT:
    case VTK_DOUBLE: // converted to float on upload
      f.InternalFormat = GL_R32F;
      f.Format = GL_RED;
      f.DataType = GL_FLOAT;
      f.UploadVTKType = VTK_FLOAT;
      f.BytesPerTexel = 4;
      f.Kind = ValueKind::Float;
      return true;
    default:
      return false;
  }
}

// The #defines that select the value type in vtkHistoPyramidBase_fs.glsl.
const char* ValueTypeDefines(ValueKind kind)
{
  switch (kind)
  {
    case ValueKind::Signed:
      return "#define VALUE_SAMPLER isampler3D\n#define VALUE_TYPE int\n";
    case ValueKind::Unsigned:
      return "#define VALUE_SAMPLER usampler3D\n#define VALUE_TYPE uint\n";
    case ValueKind::Float:
    default:
      return "#define VALUE_SAMPLER sampler3D\n#define VALUE_TYPE float\n#define VALUE_IS_FLOAT "
             "1\n";
  }
}

// Thresholds t of the texture's value type with, for every value v of that
// type, (v < t) == (v < iso) and (t <= v) == (iso <= v), so that the base
// pass counts exactly what the CPU counts in double precision. Isovalues that
// can cross no cell of the type's range (and NaN ones) are left out.
struct Thresholds
{
  std::vector<GLint> Ints;
  std::vector<GLuint> UInts;
  std::vector<GLfloat> Floats;
  int Count = 0;
};

Thresholds MakeThresholds(const VolumeFormat& f, const std::vector<double>& isovalues)
{
  Thresholds t;
  for (double iso : isovalues)
  {
    if (std::isnan(iso))
    {
      continue;
    }
    if (f.Kind == ValueKind::Float)
    {
      // The smallest float not below iso (+inf above the float range).
      float value;
      if (iso > static_cast<double>(FLT_MAX))
      {
        value = std::numeric_limits<float>::infinity();
      }
      else if (iso < -static_cast<double>(FLT_MAX))
      {
        value = -FLT_MAX;
      }
      else
      {
        value = static_cast<float>(iso);
        if (static_cast<double>(value) < iso)
        {
          value = std::nextafter(value, std::numeric_limits<float>::infinity());
        }
      }
      t.Floats.push_back(value);
    }
    else
    {
      // For integers v: v < iso <=> v < ceil(iso), iso <= v <=> ceil(iso) <= v.
      // A threshold above the maximum, or at or below the minimum, never
      // satisfies min < t <= max.
      const double c = std::ceil(iso);
      if (c > f.Max || c <= f.Min)
      {
        continue;
      }
      if (f.Kind == ValueKind::Signed)
      {
        t.Ints.push_back(static_cast<GLint>(c));
      }
      else
      {
        t.UInts.push_back(static_cast<GLuint>(c));
      }
    }
    ++t.Count;
  }
  return t;
}

// Saves a glPixelStorei parameter and restores it through vtkOpenGLState.
class ScopedPixelStore
{
public:
  ScopedPixelStore(vtkOpenGLState* state, GLenum name)
    : State(state)
    , Name(name)
  {
    glGetIntegerv(name, &this->Saved);
  }
  ~ScopedPixelStore() { this->State->vtkglPixelStorei(this->Name, this->Saved); }
  ScopedPixelStore(const ScopedPixelStore&) = delete;
  ScopedPixelStore& operator=(const ScopedPixelStore&) = delete;

private:
  vtkOpenGLState* State;
  GLenum Name;
  GLint Saved = 0;
};

// Rebinds, through the shader cache (so that the cache and OpenGL agree), the
// program that was bound when the scope began.
class ScopedProgram
{
public:
  explicit ScopedProgram(vtkOpenGLRenderWindow* win)
    : Window(win)
    , Previous(win->GetShaderCache()->GetLastShaderBound())
  {
  }
  ~ScopedProgram()
  {
    if (this->Previous && this->Previous != this->Window->GetShaderCache()->GetLastShaderBound())
    {
      this->Window->GetShaderCache()->ReadyShaderProgram(this->Previous);
    }
  }
  ScopedProgram(const ScopedProgram&) = delete;
  ScopedProgram& operator=(const ScopedProgram&) = delete;

private:
  vtkOpenGLRenderWindow* Window;
  vtkShaderProgram* Previous;
};

// All the render state of the passes, saved at construction and restored at
// destruction, with the passes' own settings applied in between.
class ScopedPassState
{
public:
  explicit ScopedPassState(vtkOpenGLState* ostate)
    : ActiveTexture(ostate)
    , Viewport(ostate)
    , ColorMask(ostate)
    , DepthTest(ostate, GL_DEPTH_TEST)
    , Blend(ostate, GL_BLEND)
    , ScissorTest(ostate, GL_SCISSOR_TEST)
    , StencilTest(ostate, GL_STENCIL_TEST)
    , CullFace(ostate, GL_CULL_FACE)
    , UnpackAlignment(ostate, GL_UNPACK_ALIGNMENT)
    , PackAlignment(ostate, GL_PACK_ALIGNMENT)
    , UnpackBuffer(GL_PIXEL_UNPACK_BUFFER, GL_PIXEL_UNPACK_BUFFER_BINDING)
    , PackBuffer(GL_PIXEL_PACK_BUFFER, GL_PIXEL_PACK_BUFFER_BINDING)
  {
    ostate->vtkglDisable(GL_DEPTH_TEST);
    ostate->vtkglDisable(GL_BLEND);
    ostate->vtkglDisable(GL_SCISSOR_TEST);
    ostate->vtkglDisable(GL_STENCIL_TEST);
    ostate->vtkglDisable(GL_CULL_FACE);
    ostate->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    ostate->vtkglPixelStorei(GL_PACK_ALIGNMENT, 4);
  }

private:
  vtkOpenGLState::ScopedglActiveTexture ActiveTexture;
  vtkOpenGLState::ScopedglViewport Viewport;
  vtkOpenGLState::ScopedglColorMask ColorMask;
  vtkOpenGLState::ScopedglEnableDisable DepthTest;
  vtkOpenGLState::ScopedglEnableDisable Blend;
  vtkOpenGLState::ScopedglEnableDisable ScissorTest;
  vtkOpenGLState::ScopedglEnableDisable StencilTest;
  vtkOpenGLState::ScopedglEnableDisable CullFace;
  ScopedPixelStore UnpackAlignment;
  ScopedPixelStore PackAlignment;
  ScopedBufferUnbind UnpackBuffer;
  ScopedBufferUnbind PackBuffer;
};

// Keeps a texture bound to a texture unit for the scope.
class ScopedTextureActive
{
public:
  explicit ScopedTextureActive(vtkTextureObject* tex)
    : Texture(tex)
  {
    this->Texture->Activate();
  }
  ~ScopedTextureActive() { this->Texture->Deactivate(); }
  ScopedTextureActive(const ScopedTextureActive&) = delete;
  ScopedTextureActive& operator=(const ScopedTextureActive&) = delete;

private:
  vtkTextureObject* Texture;
};

int NextPowerOfTwo(int n)
{
  int p = 1;
  while (p < n)
  {
    p *= 2;
  }
  return p;
}

// vtkShaderProgram has no ivec3 setter: set one on the bound program.
void SetUniformIVec3(vtkShaderProgram* program, const char* name, const int v[3])
{
  const GLint location = program->FindUniform(name);
  if (location >= 0)
  {
    glUniform3i(location, v[0], v[1], v[2]);
  }
}

void SetNearestClamp(vtkTextureObject* tex)
{
  tex->SetMinificationFilter(vtkTextureObject::Nearest);
  tex->SetMagnificationFilter(vtkTextureObject::Nearest);
  tex->SetWrapS(vtkTextureObject::ClampToEdge);
  tex->SetWrapT(vtkTextureObject::ClampToEdge);
  tex->SetWrapR(vtkTextureObject::ClampToEdge);
}
} // anonymous namespace

//------------------------------------------------------------------------------
// The OpenGL objects. They all live in the context of Window, the window of
// the last UploadVolume() (a weak reference: the owner releases them with
// ReleaseGraphicsResources() while the window is alive).
struct vtkOpenGLHistoPyramid::Internals
{
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;

  // The volume.
  vtkSmartPointer<vtkTextureObject> Volume;
  VolumeFormat Format;
  int PointDims[3] = { 0, 0, 0 };

  // The pyramid: one GL_R32UI 3D texture per level, base first.
  std::vector<vtkSmartPointer<vtkTextureObject>> Levels;
  std::vector<std::array<int, 3>> LevelSizes;
  bool Built = false;
  std::uint64_t Total = 0;

  // The passes.
  vtkSmartPointer<vtkOpenGLFramebufferObject> FBO;
  std::unique_ptr<vtkOpenGLQuadHelper> BaseQuad;
  ValueKind BaseQuadKind = ValueKind::Float;
  std::unique_ptr<vtkOpenGLQuadHelper> ReduceQuad;

  void ReleaseLevels(vtkWindow* win)
  {
    for (auto& level : this->Levels)
    {
      level->ReleaseGraphicsResources(win);
    }
    this->Levels.clear();
    this->LevelSizes.clear();
    this->Built = false;
    this->Total = 0;
  }

  void ReleaseAll(vtkWindow* win)
  {
    this->ReleaseLevels(win);
    if (this->Volume)
    {
      this->Volume->ReleaseGraphicsResources(win);
      this->Volume = nullptr;
    }
    this->PointDims[0] = this->PointDims[1] = this->PointDims[2] = 0;
    // The programs belong to the window's shader cache: free their GL
    // objects so that the cache recompiles them if they are asked for again.
    for (auto* quad : { this->BaseQuad.get(), this->ReduceQuad.get() })
    {
      if (quad)
      {
        if (quad->Program)
        {
          quad->Program->ReleaseGraphicsResources(win);
        }
        quad->ReleaseGraphicsResources(win);
      }
    }
    this->BaseQuad.reset();
    this->ReduceQuad.reset();
    if (this->FBO)
    {
      this->FBO->ReleaseGraphicsResources(win);
      this->FBO = nullptr;
    }
    this->Window = nullptr;
  }

  // Ready (compile or rebind) a pass program, creating its quad helper on
  // first use. Returns the bound program, or nullptr when it does not build.
  static vtkShaderProgram* ReadyPass(
    vtkOpenGLRenderWindow* win, std::unique_ptr<vtkOpenGLQuadHelper>& quad, const std::string& fs)
  {
    if (!quad)
    {
      // Ready it through the cache first so that a compile failure is caught
      // here rather than inside the quad helper's vertex array set-up.
      const std::string vs = vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader();
      if (!win->GetShaderCache()->ReadyShaderProgram(vs.c_str(), fs.c_str(), ""))
      {
        return nullptr;
      }
      quad = std::make_unique<vtkOpenGLQuadHelper>(win, vs.c_str(), fs.c_str(), "");
    }
    if (!quad->Program)
    {
      return nullptr;
    }
    return win->GetShaderCache()->ReadyShaderProgram(quad->Program);
  }
};

//------------------------------------------------------------------------------
vtkOpenGLHistoPyramid::vtkOpenGLHistoPyramid()
  : Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkOpenGLHistoPyramid::~vtkOpenGLHistoPyramid()
{
  // Owners normally call ReleaseGraphicsResources() first; if they did not and
  // the window is still alive, free the OpenGL objects in its context.
  if (this->Impl->Window)
  {
    ScopedContext context(this->Impl->Window);
    this->Impl->ReleaseAll(this->Impl->Window);
  }
}

//------------------------------------------------------------------------------
std::uint64_t vtkOpenGLHistoPyramid::GetTotal() const
{
  return this->Impl->Built ? this->Impl->Total : 0;
}

//------------------------------------------------------------------------------
int vtkOpenGLHistoPyramid::GetNumberOfLevels() const
{
  return this->Impl->Built ? static_cast<int>(this->Impl->Levels.size()) : 0;
}

//------------------------------------------------------------------------------
std::uint64_t vtkOpenGLHistoPyramid::GetGPUMemoryBytes() const
{
  const Internals& impl = *this->Impl;
  std::uint64_t bytes = 0;
  if (impl.Volume)
  {
    bytes += static_cast<std::uint64_t>(impl.PointDims[0]) * impl.PointDims[1] * impl.PointDims[2] *
      impl.Format.BytesPerTexel;
  }
  for (const auto& size : impl.LevelSizes)
  {
    bytes += static_cast<std::uint64_t>(size[0]) * size[1] * size[2] * sizeof(std::uint32_t);
  }
  return bytes;
}

//------------------------------------------------------------------------------
void vtkOpenGLHistoPyramid::ReleaseGraphicsResources(vtkWindow* win)
{
  this->Impl->ReleaseAll(win);
  this->Modified();
}

//------------------------------------------------------------------------------
bool vtkOpenGLHistoPyramid::UploadVolume(
  vtkOpenGLRenderWindow* renWin, vtkDataArray* scalars, const int pointDims[3])
{
  Internals& impl = *this->Impl;
  if (!renWin || !scalars || !pointDims)
  {
    vtkErrorMacro("UploadVolume needs a window, an array and dimensions.");
    return false;
  }
  if (pointDims[0] < 2 || pointDims[1] < 2 || pointDims[2] < 2)
  {
    vtkErrorMacro("The volume must have at least 2 points per axis, not "
      << pointDims[0] << "x" << pointDims[1] << "x" << pointDims[2] << ".");
    return false;
  }
  const vtkIdType numPoints = static_cast<vtkIdType>(pointDims[0]) * pointDims[1] * pointDims[2];
  if (scalars->GetNumberOfComponents() != 1 || scalars->GetNumberOfTuples() != numPoints)
  {
    vtkErrorMacro("Expected " << numPoints << " single-component values, got "
                              << scalars->GetNumberOfTuples() << " tuples of "
                              << scalars->GetNumberOfComponents() << " components.");
    return false;
  }
  VolumeFormat format;
  if (!ChooseFormat(scalars->GetDataType(), format))
  {
    vtkErrorMacro("Unsupported scalar type " << scalars->GetDataTypeAsString() << ".");
    return false;
  }
  if (impl.Window && impl.Window != renWin)
  {
    ScopedContext oldContext(impl.Window);
    impl.ReleaseAll(impl.Window);
  }

  // Double data is converted to float; every other type goes up as it is.
  std::vector<float> converted;
  void* data = scalars->GetVoidPointer(0);
  if (scalars->GetDataType() == VTK_DOUBLE)
  {
    const double* d = static_cast<const double*>(data);
    converted.assign(d, d + numPoints);
    data = converted.data();
  }

  ScopedContext context(renWin);
  vtkOpenGLState* ostate = renWin->GetState();
  TakeGLErrors();
  ScopedPassState savedState(ostate);

  // A new size invalidates the levels (and a new window everything, above).
  const bool sameSize = impl.PointDims[0] == pointDims[0] && impl.PointDims[1] == pointDims[1] &&
    impl.PointDims[2] == pointDims[2];
  if (!sameSize)
  {
    impl.ReleaseLevels(renWin);
  }
  impl.Built = false;
  impl.Total = 0;
  if (impl.Volume)
  {
    impl.Volume->ReleaseGraphicsResources(renWin);
  }
  impl.Window = renWin;
  impl.Volume = vtkSmartPointer<vtkTextureObject>::New();
  impl.Volume->SetContext(renWin);
  impl.Volume->SetInternalFormat(format.InternalFormat);
  impl.Volume->SetFormat(format.Format);
  impl.Volume->SetDataType(format.DataType);
  SetNearestClamp(impl.Volume);
  const bool created = impl.Volume->Create3DFromRaw(static_cast<unsigned int>(pointDims[0]),
    static_cast<unsigned int>(pointDims[1]), static_cast<unsigned int>(pointDims[2]), 1,
    format.UploadVTKType, data);
  const std::string errors = TakeGLErrors();
  if (!created || !errors.empty())
  {
    vtkErrorMacro("Cannot upload the " << pointDims[0] << "x" << pointDims[1] << "x" << pointDims[2]
                                       << " volume as a 3D texture"
                                       << (errors.empty() ? "" : ": " + errors));
    impl.Volume->ReleaseGraphicsResources(renWin);
    impl.Volume = nullptr;
    impl.PointDims[0] = impl.PointDims[1] = impl.PointDims[2] = 0;
    return false;
  }
  impl.Format = format;
  for (int a = 0; a < 3; ++a)
  {
    impl.PointDims[a] = pointDims[a];
  }
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
bool vtkOpenGLHistoPyramid::Build(
  vtkOpenGLRenderWindow* renWin, const std::vector<double>& isovalues)
{
  Internals& impl = *this->Impl;
  impl.Built = false;
  impl.Total = 0;
  if (!renWin || !impl.Volume || impl.Window != renWin)
  {
    vtkErrorMacro("Build needs a volume uploaded to the same window first.");
    return false;
  }
  if (isovalues.empty() || isovalues.size() > static_cast<std::size_t>(MaximumNumberOfIsovalues))
  {
    vtkErrorMacro("Build takes 1 to " << MaximumNumberOfIsovalues << " isovalues, not "
                                      << isovalues.size() << ".");
    return false;
  }
  const Thresholds thresholds = MakeThresholds(impl.Format, isovalues);

  ScopedContext context(renWin);
  vtkOpenGLState* ostate = renWin->GetState();
  TakeGLErrors();
  ScopedProgram savedProgram(renWin);
  ScopedPassState savedState(ostate);

  // 1. The level textures, allocated once per volume size.
  const int cells[3] = { impl.PointDims[0] - 1, impl.PointDims[1] - 1, impl.PointDims[2] - 1 };
  if (impl.Levels.empty())
  {
    std::array<int, 3> size = { NextPowerOfTwo(cells[0]), NextPowerOfTwo(cells[1]),
      NextPowerOfTwo(cells[2]) };
    while (true)
    {
      auto level = vtkSmartPointer<vtkTextureObject>::New();
      level->SetContext(renWin);
      level->SetInternalFormat(GL_R32UI);
      level->SetFormat(GL_RED_INTEGER);
      level->SetDataType(GL_UNSIGNED_INT);
      SetNearestClamp(level);
      if (!level->Allocate3D(static_cast<unsigned int>(size[0]), static_cast<unsigned int>(size[1]),
            static_cast<unsigned int>(size[2]), 1, VTK_UNSIGNED_INT))
      {
        vtkErrorMacro("Cannot allocate a " << size[0] << "x" << size[1] << "x" << size[2]
                                           << " GL_R32UI 3D texture: " << TakeGLErrors());
        impl.ReleaseLevels(renWin);
        return false;
      }
      impl.Levels.push_back(level);
      impl.LevelSizes.push_back(size);
      if (size[0] == 1 && size[1] == 1 && size[2] == 1)
      {
        break;
      }
      for (int& s : size)
      {
        s = s > 1 ? s / 2 : 1;
      }
    }
  }

  // 2. The programs.
  if (impl.BaseQuad && impl.BaseQuadKind != impl.Format.Kind)
  {
    impl.BaseQuad->ReleaseGraphicsResources(renWin);
    impl.BaseQuad.reset();
  }
  std::string baseFS = vtkHistoPyramidBase_fs;
  vtkShaderProgram::Substitute(
    baseFS, "//VTK::HistoPyramidValueType::Dec", ValueTypeDefines(impl.Format.Kind));
  vtkShaderProgram* baseProgram = Internals::ReadyPass(renWin, impl.BaseQuad, baseFS);
  impl.BaseQuadKind = impl.Format.Kind;
  vtkShaderProgram* reduceProgram =
    Internals::ReadyPass(renWin, impl.ReduceQuad, vtkHistoPyramidReduce_fs);
  if (!baseProgram || !reduceProgram)
  {
    vtkErrorMacro("The HistoPyramid shaders do not build.");
    return false;
  }

  // 3. The framebuffer: one slice of one level attached at a time.
  if (!impl.FBO)
  {
    impl.FBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    impl.FBO->SetContext(renWin);
  }
  ScopedFramebufferBindings savedBindings(impl.FBO);
  impl.FBO->Bind();
  impl.FBO->ActivateDrawBuffers(1);
  impl.FBO->ActivateReadBuffer(0);
  auto attach = [&](int level, int slice) -> bool
  {
    glFramebufferTextureLayer(
      GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, impl.Levels[level]->GetHandle(), 0, slice);
    if (slice == 0)
    {
      const char* desc = nullptr;
      if (!vtkOpenGLFramebufferObject::GetFrameBufferStatus(GL_FRAMEBUFFER, desc))
      {
        vtkErrorMacro("The GL_R32UI render target of level "
          << level << " is incomplete: " << (desc ? desc : "unknown status"));
        return false;
      }
    }
    return true;
  };
  struct Detach
  {
    ~Detach() { glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, 0, 0, 0); }
  } detachOnExit;

  // 4. Base pass: one quad per z-slice of level 0.
  {
    renWin->GetShaderCache()->ReadyShaderProgram(baseProgram);
    ScopedTextureActive volumeActive(impl.Volume);
    const auto& size = impl.LevelSizes[0];
    baseProgram->SetUniformi("volume", impl.Volume->GetTextureUnit());
    baseProgram->SetUniformi("numberOfThresholds", thresholds.Count);
    SetUniformIVec3(baseProgram, "cellDimensions", cells);
    const int sliceSize[2] = { size[0], size[1] };
    baseProgram->SetUniform2i("sliceSize", sliceSize);
    const GLint location = baseProgram->FindUniform("thresholds");
    if (thresholds.Count > 0 && location >= 0)
    {
      switch (impl.Format.Kind)
      {
        case ValueKind::Signed:
          glUniform1iv(location, thresholds.Count, thresholds.Ints.data());
          break;
        case ValueKind::Unsigned:
          glUniform1uiv(location, thresholds.Count, thresholds.UInts.data());
          break;
        case ValueKind::Float:
          glUniform1fv(location, thresholds.Count, thresholds.Floats.data());
          break;
      }
    }
    ostate->vtkglViewport(0, 0, size[0], size[1]);
    for (int z = 0; z < size[2]; ++z)
    {
      if (!attach(0, z))
      {
        return false;
      }
      baseProgram->SetUniformi("slice", z);
      impl.BaseQuad->Render();
    }
  }

  // 5. Reduction passes: level l from level l - 1.
  renWin->GetShaderCache()->ReadyShaderProgram(reduceProgram);
  for (std::size_t l = 1; l < impl.Levels.size(); ++l)
  {
    ScopedTextureActive lowerActive(impl.Levels[l - 1]);
    const auto& size = impl.LevelSizes[l];
    const auto& lower = impl.LevelSizes[l - 1];
    const int factor[3] = { lower[0] / size[0], lower[1] / size[1], lower[2] / size[2] };
    const int sliceSize[2] = { size[0], size[1] };
    reduceProgram->SetUniformi("lowerLevel", impl.Levels[l - 1]->GetTextureUnit());
    SetUniformIVec3(reduceProgram, "factor", factor);
    reduceProgram->SetUniform2i("sliceSize", sliceSize);
    ostate->vtkglViewport(0, 0, size[0], size[1]);
    for (int z = 0; z < size[2]; ++z)
    {
      if (!attach(static_cast<int>(l), z))
      {
        return false;
      }
      reduceProgram->SetUniformi("slice", z);
      impl.ReduceQuad->Render();
    }
  }

  // 6. Read back the top node only.
  GLuint top = 0;
  if (!attach(static_cast<int>(impl.Levels.size()) - 1, 0))
  {
    return false;
  }
  glReadPixels(0, 0, 1, 1, GL_RED_INTEGER, GL_UNSIGNED_INT, &top);
  const std::string errors = TakeGLErrors();
  if (!errors.empty())
  {
    vtkErrorMacro("Building the HistoPyramid failed: " << errors);
    return false;
  }
  impl.Total = top;
  impl.Built = true;
  return true;
}

//------------------------------------------------------------------------------
bool vtkOpenGLHistoPyramid::ReadLevel(int level, std::vector<std::uint32_t>& counts, int size[3])
{
  Internals& impl = *this->Impl;
  if (!impl.Built || level < 0 || level >= static_cast<int>(impl.Levels.size()) || !impl.Window)
  {
    return false;
  }
  const auto& s = impl.LevelSizes[level];
  for (int a = 0; a < 3; ++a)
  {
    size[a] = s[a];
  }
  counts.assign(static_cast<std::size_t>(s[0]) * s[1] * s[2], 0u);

  vtkOpenGLRenderWindow* win = impl.Window;
  ScopedContext context(win);
  TakeGLErrors();
  ScopedPassState savedState(win->GetState());
  ScopedFramebufferBindings savedBindings(impl.FBO);
  impl.FBO->Bind();
  impl.FBO->ActivateReadBuffer(0);
  const std::size_t sliceCount = static_cast<std::size_t>(s[0]) * s[1];
  for (int z = 0; z < s[2]; ++z)
  {
    glFramebufferTextureLayer(
      GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, impl.Levels[level]->GetHandle(), 0, z);
    glReadPixels(0, 0, s[0], s[1], GL_RED_INTEGER, GL_UNSIGNED_INT, counts.data() + z * sliceCount);
  }
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, 0, 0, 0);
  const std::string errors = TakeGLErrors();
  if (!errors.empty())
  {
    vtkErrorMacro("Reading level " << level << " back failed: " << errors);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkOpenGLHistoPyramid::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  const Internals& impl = *this->Impl;
  os << indent << "Volume: " << impl.PointDims[0] << "x" << impl.PointDims[1] << "x"
     << impl.PointDims[2] << " points\n";
  os << indent << "NumberOfLevels: " << this->GetNumberOfLevels() << "\n";
  os << indent << "Total: " << this->GetTotal() << "\n";
  os << indent << "GPUMemoryBytes: " << this->GetGPUMemoryBytes() << "\n";
}
