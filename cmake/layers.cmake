# vrdeform_layer(NAME MODULES module... [DEPENDS layer...] [INTERNAL] [PUBLIC lib...] [PRIVATE lib...])
#
# One layer of the engine: the static library vrdeform_NAME (vrdeform::NAME) built from
# src/<module>/*.cpp of its modules, with their public headers in include/vrdeform/<module>/.
# DEPENDS names the layers below it that it links (publicly); nothing else of ours is linked, and
# the test layers.includes checks that its files include no module outside those layers.
# INTERNAL: built for the programs and tests, not installed (test doubles).
function(vrdeform_layer name)
  cmake_parse_arguments(arg "INTERNAL" "" "MODULES;DEPENDS;PUBLIC;PRIVATE" ${ARGN})
  set(sources "")
  foreach(module IN LISTS arg_MODULES)
    file(GLOB module_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${module}/*.cpp)
    list(APPEND sources ${module_sources})
  endforeach()
  set(target vrdeform_${name})
  add_library(${target} STATIC ${sources})
  add_library(vrdeform::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} POSITION_INDEPENDENT_CODE ON)
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
                                              $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
                                       PRIVATE ${PROJECT_SOURCE_DIR}/src)
  list(TRANSFORM arg_DEPENDS PREPEND vrdeform_ OUTPUT_VARIABLE below)
  target_link_libraries(${target} PUBLIC ${below} ${arg_PUBLIC} PRIVATE ${arg_PRIVATE})
  vrdeform_target_defaults(${target})

  # The modules this layer may include: its own and those of every layer below it.
  set(allowed ${arg_MODULES})
  foreach(layer IN LISTS arg_DEPENDS)
    get_property(below_modules GLOBAL PROPERTY vrdeform_layer_${layer}_allowed)
    list(APPEND allowed ${below_modules})
  endforeach()
  list(REMOVE_DUPLICATES allowed)
  set_property(GLOBAL PROPERTY vrdeform_layer_${name}_allowed ${allowed})
  set_property(GLOBAL APPEND PROPERTY vrdeform_layers "${name}")
  set_property(GLOBAL PROPERTY vrdeform_layer_${name}_modules ${arg_MODULES})

  if(NOT arg_INTERNAL)
    set_property(GLOBAL APPEND PROPERTY vrdeform_installed_layers ${name})
    install(TARGETS ${target} EXPORT vrdeform-${name}-targets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
    install(EXPORT vrdeform-${name}-targets NAMESPACE vrdeform:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vrdeform)
  endif()
endfunction()

# Writes the layers' table for the test layers.includes (tests/check_layers.cmake) into FILE:
# for each layer, its modules and the modules it may include.
function(vrdeform_write_layer_table file)
  get_property(layers GLOBAL PROPERTY vrdeform_layers)
  set(text "set(layers ${layers})\n")
  foreach(layer IN LISTS layers)
    get_property(modules GLOBAL PROPERTY vrdeform_layer_${layer}_modules)
    get_property(allowed GLOBAL PROPERTY vrdeform_layer_${layer}_allowed)
    string(APPEND text "set(modules_${layer} ${modules})\nset(allowed_${layer} ${allowed})\n")
  endforeach()
  file(WRITE ${file} "${text}")
endfunction()
