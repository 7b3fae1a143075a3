# The shared kernels must stay valid GLSL (for the Vulkan and GL backends): glslangValidator.
.PHONY: check-glsl
check-glsl:
	scripts/check-glsl
test: check-glsl
