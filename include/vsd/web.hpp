/** @file
 *  @brief vsd::web: the inspector in the browser — the database tree and tables, every property (editable
 *  where `Editable`), the 3D scene, the SOML++ nets and a timeline, served live by the process itself
 *  (link vsd::web; docs/web.md).
 */
#pragma once

#include "vsd/core.hpp"
#include "vsd/web/server.hpp"
