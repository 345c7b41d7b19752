// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file Lighting.h
 * @brief The one place a lit program gets its material and lights (no VTK).
 *
 * Every program that shades a surface (the isosurfaces' cell rasterisation,
 * and a host's triangle meshes drawn beside them) declares the same uniforms
 * (ambient, diffuse, specular, specularPower, lightDirections, lightColors;
 * see Shaders/) and takes their values from an IsosurfaceFrame, so that a
 * mesh and an isosurface of the same value shade alike.
 */
#ifndef MedicalIsosurfaces_Lighting_h
#define MedicalIsosurfaces_Lighting_h

#include "IsosurfaceFrame.h"

namespace mediso
{
namespace glcore
{
class Program;
}

/// Sets the bound lit program's material and light uniforms from the frame.
void SetLightingUniforms(glcore::Program& program, const IsosurfaceFrame& frame);

} // namespace mediso

#endif
