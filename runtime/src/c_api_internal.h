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
}  // namespace aggrelod::runtime::capi
