# Shared by the consumer projects: links `consumer` to vsd::<m> for each module of @p modules that is a
# target, and tells consumer_main.cpp which ones it has (CONSUMER_HAS_<M>).
function(vsd_consumer_link modules)
  foreach(m IN LISTS modules)
    if(TARGET vsd::${m} AND NOT m STREQUAL "core")
      string(TOUPPER ${m} upper)
      target_link_libraries(consumer PRIVATE vsd::${m})
      target_compile_definitions(consumer PRIVATE CONSUMER_HAS_${upper}=1)
    endif()
  endforeach()
endfunction()
