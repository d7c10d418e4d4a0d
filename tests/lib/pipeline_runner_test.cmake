# The runner runs the stages' registered commands (apps/) on a phantom.
target_link_libraries(${test_name} PRIVATE articula_commands articula_phantom articula_imaging)
