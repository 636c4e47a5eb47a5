# The meta-information layer: signals, MetaTypes, Values, classes (built-in and run-time), the Registry.
vsd_add_test_suite(vsd_meta_tests
  core/signal_test.cpp
  core/meta_type_test.cpp
  core/value_test.cpp
  core/meta_instance_test.cpp
  core/runtime_class_test.cpp
  core/registry_test.cpp
  core/class_names_test.cpp
  core/runtime_type_test.cpp
  core/vector_access_test.cpp
)
