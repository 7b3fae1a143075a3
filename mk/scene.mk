# The host-scene example (examples/scene.c): meshes with a depth buffer and a placed smoke cloud
# on the GL backend, composited in linear HDR.
#   make scene         build/scene, then a fixed orbit under xvfb-run written to out/scene.png
#   make test-scene    the same at 320x180 into build/gl/scene.png with --check: the cloud is
#                      finite, covers part of the image and not all of it; the PNG is lit (T)
.PHONY: scene test-scene

$(B)/scene: examples/scene.c examples/hd_png.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) -Iexamples $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) -lglfw -lOpenGL -lEGL

scene: $(B)/scene
	@mkdir -p out
	xvfb-run -a -s "-screen 0 1280x720x24" $(B)/scene --size 960x540 --frames 48 --out out/scene.png

test-scene: $(B)/scene $(B)/pngcmp
	@mkdir -p $(B)/gl
	xvfb-run -a -s "-screen 0 640x480x24" $(B)/scene --size 320x180 --frames 24 --check --out $(B)/gl/scene.png
	$(B)/pngcmp --nonblank $(B)/gl/scene.png

TEST_PROGRAMS += $(B)/scene
test: test-scene
