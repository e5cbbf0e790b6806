// SPDX-License-Identifier: AGPL-3.0-or-later
// Overrides TetGen's weak terminatetetgen(): the Debian library frees its mesh and then
// throws, and the stack-held mesh frees it again while unwinding (docs/design.md §6). This
// version only throws the code. It must not include tetgen.h (the declaration differs).
class tetgenmesh;

void terminatetetgen(tetgenmesh*, int code) { throw code; }
