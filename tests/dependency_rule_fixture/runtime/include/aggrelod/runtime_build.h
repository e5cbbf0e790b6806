// SPDX-License-Identifier: AGPL-3.0-or-later
// Fixture: the bake -> runtime contract, the one runtime header the module may include.
#pragma once
