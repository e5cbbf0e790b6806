// SPDX-License-Identifier: MIT
// Fixture: the bake -> runtime contract, the one runtime header the module may include.
#pragma once
