// SPDX-License-Identifier: BSD-3-Clause
#include "Lighting.h"

#include "GLObjects.h"

namespace mediso
{

void SetLightingUniforms(glcore::Program& program, const IsosurfaceFrame& frame)
{
  program.Set("ambient", frame.Ambient);
  program.Set("diffuse", frame.Diffuse);
  program.Set("specular", frame.Specular);
  program.Set("specularPower", frame.SpecularPower);
  program.Set3fv("lightDirections", MaximumLights, &frame.LightDirections[0][0]);
  program.Set3fv("lightColors", MaximumLights, &frame.LightColors[0][0]);
}

} // namespace mediso
