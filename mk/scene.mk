# The host-scene examples: meshes with a depth buffer and a placed smoke cloud, composited in
# linear HDR. examples/scene.c on the GL backend (GLFW, a window under Xvfb), examples/scene_vulkan.c
# on the Vulkan backend (its own instance and device, offscreen, one command buffer per frame).
#   make scene              build/scene, then a fixed orbit under xvfb-run written to out/scene.png
#   make test-scene         the same at 320x180 into build/gl/scene.png with --check: the cloud is
#                           finite, covers part of the image and not all of it; the PNG is lit (T)
#   make scene-vulkan       build/scene_vulkan, the same orbit offscreen into out/scene_vulkan.png
#   make test-scene-vulkan  at 256x144 under VK_LAYER_KHRONOS_validation (+ synchronization
#                           validation) with --check: no validation message; against the image
#                           without depth, sky and ground match, the box in front hides the
#                           cloud, the post in it cuts it; the plume is finite and covers part
#                           of the image; the PNG is lit (T)
.PHONY: scene test-scene scene-vulkan test-scene-vulkan

$(B)/scene: examples/scene.c examples/hd_png.h examples/hd_scene_common.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) -Iexamples $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) -lglfw -lOpenGL -lEGL

scene: $(B)/scene
	@mkdir -p out
	xvfb-run -a -s "-screen 0 1280x720x24" $(B)/scene --size 960x540 --frames 48 --out out/scene.png

test-scene: $(B)/scene $(B)/pngcmp
	@mkdir -p $(B)/gl
	xvfb-run -a -s "-screen 0 640x480x24" $(B)/scene --size 320x180 --frames 24 --check --out $(B)/gl/scene.png
	$(B)/pngcmp --nonblank $(B)/gl/scene.png

# examples/scene_vulkan.glsl's stages, compiled by glslangValidator into one header of SPIR-V arrays
# (scene_spv_NAME), built here rather than committed
SCENE_VK_STAGES := mesh_vs:vert:MESH_VS mesh_fs:frag:MESH_FS quad_vs:vert:QUAD_VS blend_fs:frag:BLEND_FS tonemap_fs:frag:TONEMAP_FS
$(B)/scene_vulkan_spv.h: examples/scene_vulkan.glsl mk/scene.mk | $(B)
	@rm -f $@.tmp
	@for s in $(SCENE_VK_STAGES); do set -- $$(echo $$s | tr : ' '); \
	    glslangValidator -V -S $$2 -D$$3 --vn scene_spv_$$1 -o $(B)/scene_spv_$$1.h $< >/dev/null || exit 1; \
	    cat $(B)/scene_spv_$$1.h >> $@.tmp; rm -f $(B)/scene_spv_$$1.h; done
	@mv $@.tmp $@

$(B)/scene_vulkan: examples/scene_vulkan.c $(B)/scene_vulkan_spv.h examples/hd_png.h examples/hd_scene_common.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) -Iexamples -I$(B) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(VK_LDLIBS)

scene-vulkan: $(B)/scene_vulkan
	@mkdir -p out
	$(B)/scene_vulkan --size 960x540 --frames 48 --out out/scene_vulkan.png

test-scene-vulkan: $(B)/scene_vulkan $(B)/pngcmp
	@mkdir -p $(B)/vulkan
	@rm -f $(B)/vulkan/scene_vulkan.png
	$(B)/scene_vulkan --size 256x144 --frames 24 --validate --check --out $(B)/vulkan/scene_vulkan.png
	@if [ -f $(B)/vulkan/scene_vulkan.png ]; then $(B)/pngcmp --nonblank $(B)/vulkan/scene_vulkan.png; fi

TEST_PROGRAMS += $(B)/scene $(B)/scene_vulkan
test: test-scene test-scene-vulkan
