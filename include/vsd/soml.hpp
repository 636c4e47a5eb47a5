/** @file
 *  @brief vsd::soml: the SOML++ language (link vsd::soml). See docs/soml.md.
 */
#pragma once

#include "vsd/soml/ast.hpp"
#include "vsd/soml/checker.hpp"
#include "vsd/soml/debugger.hpp"
#include "vsd/soml/fwd.hpp"
#include "vsd/soml/lexer.hpp"
#include "vsd/soml/module.hpp"
#include "vsd/soml/net_classes.hpp"
#include "vsd/soml/parser.hpp"
#include "vsd/soml/runtime.hpp"
#include "vsd/soml/source.hpp"
#include "vsd/soml/types.hpp"
