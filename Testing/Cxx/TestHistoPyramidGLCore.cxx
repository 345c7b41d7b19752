// SPDX-License-Identifier: BSD-3-Clause
// The GPU core's HistoPyramid against the CPU model, node for node (see
// HistoPyramidGLChecks.h), with no VTK and no X display: on an EGL context
// of OpenGL ES 3.0 (the WebGL2 subset) or of OpenGL 3.2 core.
//   TestHistoPyramidGLCore es|gl
//  - exit 0 when everything matches;
//  - exit 125 (skip), printing "SKIP: <reason>", where no such EGL context
//    can be made;
//  - exit 1 on any mismatch.
#include "HeadlessContext.h"
#include "HistoPyramidGLChecks.h"

#include <cstring>
#include <iostream>

int main(int argc, char* argv[])
{
  if (argc != 2 || (std::strcmp(argv[1], "es") != 0 && std::strcmp(argv[1], "gl") != 0))
  {
    std::cerr << "usage: " << argv[0] << " es|gl\n";
    return 2;
  }
  const bool es = std::strcmp(argv[1], "es") == 0;
  std::string error;
  auto context = mediso::headless::HeadlessContext::Create(
    es ? mediso::headless::ContextApi::ES3 : mediso::headless::ContextApi::GL32, error);
  if (!context)
  {
    std::cout << "SKIP: " << error << "\n";
    return 125;
  }
  std::cout << "EGL platform: " << context->GetPlatform() << "\n";
  return pyramid_checks::RunAll(context->GetGLApi(),
    es ? "TestHistoPyramidGLCore es passed" : "TestHistoPyramidGLCore gl passed");
}
