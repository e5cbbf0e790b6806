// SPDX-License-Identifier: AGPL-3.0-or-later
// The module's 3-vector of doubles: GLM's dvec3, zero-initialised like a plain struct of three
// doubles. dot, cross and length are GLM's; they evaluate in the same order as the
// hand-written a.x * b.x + a.y * b.y + a.z * b.z, so results are bit for bit those of that
// form. The one place the module includes GLM.
#pragma once

#ifndef GLM_FORCE_CTOR_INIT
#define GLM_FORCE_CTOR_INIT
#endif
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

// GLM_FORCE_CTOR_INIT works only when this is the first GLM include of the file.
static_assert(GLM_CONFIG_CTOR_INIT != GLM_CTOR_INIT_DISABLE, "vec3.h must be included before any other GLM header");

namespace aggrelod::detail {

using Vec3 = glm::dvec3;
using glm::cross;
using glm::dot;
using glm::length;

}  // namespace aggrelod::detail
