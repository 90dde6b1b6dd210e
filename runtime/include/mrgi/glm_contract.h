/// \file
/// The contract between mrgi's public headers and an app's GLM. The public API passes GLM
/// vectors, matrices and quaternions by value (positions, poses, colours), so an app and libmrgi
/// must agree on their layout: GLM 0.9.9 or newer with its default, unaligned types. The macros
/// mrgi compiles itself with (GLM_FORCE_DEPTH_ZERO_TO_ONE, GLM_ENABLE_EXPERIMENTAL) change
/// functions, not layouts, so an app need not match them; the ones that change layouts
/// (GLM_FORCE_DEFAULT_ALIGNED_GENTYPES with GLM_FORCE_INTRINSICS, GLM_FORCE_PRECISION_*) are
/// refused here at compile time instead of corrupting every struct silently.
#pragma once
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

static_assert(GLM_VERSION >= 998, "mrgi's public API needs GLM 0.9.9.8 or newer");
static_assert(sizeof(glm::vec3) == 12 && alignof(glm::vec3) == alignof(float) &&
                  sizeof(glm::vec4) == 16 && alignof(glm::vec4) == alignof(float) &&
                  sizeof(glm::quat) == 16 && alignof(glm::quat) == alignof(float) &&
                  sizeof(glm::dvec3) == 24 && sizeof(glm::dmat4) == 128 &&
                  alignof(glm::dmat4) == alignof(double),
              "mrgi/glm_contract.h: GLM's types must have their default, unaligned layout "
              "(no GLM_FORCE_DEFAULT_ALIGNED_GENTYPES); libmrgi was built with it");
