/** @file
 *  @brief Forward declarations of the core's classes.
 */
#pragma once

#include <cstdint>

namespace vsd {
using Id = std::uint64_t;
class Error;
class MetaType;
class MetaProperty;
class MetaMethod;
class MetaInstance;
class ClassBuilder;
class Registry;
class Value;
class Instance;
class SimStateInstance;
class NamedModelInstance;
class Node;
class Extension;
class Database;
class Container;
class View;
class ElementIndex;
class SimState;
class Transaction;
class Environment;
class Module;
class Scheduler;
class Connection;
class StateContext;
class Watch;
enum class Service : std::uint8_t;
enum class Phase : int;
template <class Signature>
class Signal;
template <class Signature>
class Sink;
template <class T>
class Ref;
template <class T>
class SharedRef;
template <class T>
class RefList;
template <class T>
class SharedRefList;
}  // namespace vsd
