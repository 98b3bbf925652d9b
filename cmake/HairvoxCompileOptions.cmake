# Strict warnings and sanitizers, applied per target with hairvox_target_defaults().
# (OpenVDB's cmake/config/OpenVDBCXX.cmake and cpp-best-practices are the models.)

set(HAIRVOX_WARNINGS
    -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion
    -Wnon-virtual-dtor -Wold-style-cast -Woverloaded-virtual
    -Wimplicit-fallthrough -Wformat=2 -Wcast-align -Wmissing-declarations)
# -Wdouble-promotion with GCC only: GCC flags float operands promoted to double
# in arithmetic (the performance hazard the flag is for); Clang also flags
# every lossless float → double initialisation and argument, which the
# double-precision table integrators do on purpose.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    list(APPEND HAIRVOX_WARNINGS -Wdouble-promotion -Wduplicated-cond -Wlogical-op -Wuseless-cast)
endif()

if(HAIRVOX_SANITIZE)
    string(REPLACE "," ";" _hairvox_sanitizers "${HAIRVOX_SANITIZE}")
    foreach(s IN LISTS _hairvox_sanitizers)
        if(NOT s MATCHES "^(address|undefined|thread|leak)$")
            message(FATAL_ERROR "HAIRVOX_SANITIZE: unknown sanitizer '${s}'")
        endif()
    endforeach()
    set(HAIRVOX_SANITIZE_FLAGS -fsanitize=${HAIRVOX_SANITIZE} -fno-omit-frame-pointer
        -fno-sanitize-recover=all)
    add_compile_options(${HAIRVOX_SANITIZE_FLAGS})
    add_link_options(${HAIRVOX_SANITIZE_FLAGS})
    # Every large array (core/large_array.h) starts as 0xFF bytes, NaN as
    # floats, so that a value read before it is written fails the tests.
    add_compile_definitions(HAIRVOX_POISON_UNINITIALIZED=1)
endif()

# Apply hairvox's warning set to one of its own targets (never to dependencies).
function(hairvox_target_defaults target)
    target_compile_options(${target} PRIVATE ${HAIRVOX_WARNINGS})
    # GCC's -O2 vectorises only loops of known trip count ("very cheap"); the
    # per-fragment loops over a shader's floats run a count known at run time.
    # Element-wise loops vectorised give the same bits (no reassociation).
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
        target_compile_options(${target} PRIVATE -fvect-cost-model=dynamic)
    endif()
    if(HAIRVOX_WERROR)
        target_compile_options(${target} PRIVATE -Werror)
    endif()
endfunction()

# hairvox_add_library(name SOURCES ... DEPS ...): one static library per stage,
# exposing <stage>/include so that only linked stages can include its headers.
function(hairvox_add_library name)
    cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
    add_library(hairvox_${name} STATIC ${ARG_SOURCES})
    add_library(hairvox::${name} ALIAS hairvox_${name})
    target_include_directories(hairvox_${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
    target_link_libraries(hairvox_${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
    hairvox_target_defaults(hairvox_${name})
endfunction()

# hairvox_use_process_allocator(target): a program (never a library) links the
# process allocator, jemalloc configured by core/src/process_allocator.cpp,
# where HAIRVOX_JEMALLOC is on.
function(hairvox_use_process_allocator target)
    if(HAIRVOX_JEMALLOC)
        target_link_libraries(${target} PRIVATE hairvox_process_allocator ${JEMALLOC_LIBRARY})
    endif()
endfunction()
