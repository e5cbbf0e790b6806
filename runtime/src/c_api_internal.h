// SPDX-License-Identifier: MIT
// Shared by the two halves of the C API (c_api.cpp, c_api_collision.cpp).
#pragma once

#include <aggrelod_runtime.h>
#include <aggrelod/runtime_file.h>

#include <string>

struct aglod_file {
    aggrelod::runtime::RuntimeFile file;
};

namespace aggrelod::runtime::capi {
/// Message returned by aglod_last_error (thread-local).
std::string& lastError();
aglod_status failWith(aglod_status status, const std::string& message);

/// Largest magnitude of a world coordinate or direction component accepted by any entry:
/// inside what ray tracing (Embree) accepts, and far beyond any baked scene.
constexpr float kMaxCoordinate = 1e18f;

/// n values all finite and within kMaxCoordinate (NaN fails the comparison).
inline bool inRange(const float* v, int n) {
    for (int k = 0; k < n; ++k)
        if (!(v[k] >= -kMaxCoordinate && v[k] <= kMaxCoordinate)) return false;
    return true;
}
}  // namespace aggrelod::runtime::capi
