/** @file
 *  @brief The vsd core: meta-information, instances, references, SimStates, signals, modules.
 */
#pragma once

#include "vsd/core/container.hpp"
#include "vsd/core/database.hpp"
#include "vsd/core/declare.hpp"
#include "vsd/core/element_index.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/extension.hpp"
#include "vsd/core/flags.hpp"
#include "vsd/core/fwd.hpp"
#include "vsd/core/instance.hpp"
#include "vsd/core/meta_instance.hpp"
#include "vsd/core/meta_method.hpp"
#include "vsd/core/meta_property.hpp"
#include "vsd/core/meta_type.hpp"
#include "vsd/core/module.hpp"
#include "vsd/core/named_model_instance.hpp"
#include "vsd/core/node.hpp"
#include "vsd/core/reference.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/scheduler.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/core/transaction.hpp"
#include "vsd/core/type_builder.hpp"
#include "vsd/core/value.hpp"
