// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod-tetgen: runs TetGen for the bake in a process of its own, started with
// posix_spawn (see tetgen_backend.h, tetgenHelperMain).
#include "tetgen_backend.h"

int main(int argc, char** argv) { return aggrelod::detail::tetgenHelperMain(argc, argv); }
