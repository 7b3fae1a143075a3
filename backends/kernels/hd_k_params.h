/* hd_k_params.h - the parameter block every kernel reads (shared source; no #include here).
   Only 16-byte vectors, so C, OpenCL and std140 GLSL agree on the layout. The host fills it in
   src/hd_kparams.h (hd__fill_kparams). */
/* How the volume (vol) is stored: HD_VOL_F32 its normalised values, the others the raw voxels,
   mapped by vnorm (hdk_voxel, hd_k_common.h). */
#define HD_VOL_F32 0
#define HD_VOL_U8 1
#define HD_VOL_U16 2
#define HD_VOL_I16 3
HD_PARAMS_BEGIN
HD_PARAM_I4(dims)       /* volume dims x, y, z; w = TF entry count */
HD_PARAM_I4(gdims)      /* illumination grid dims x, y, z; w = channels (1 or 3) */
HD_PARAM_I4(mdims)      /* majorant grid dims x, y, z; w = voxels per cell edge */
HD_PARAM_I4(counts)     /* x = lights, y = tracking (1 ratio, 2 delta), z = flags, w = bounces */
HD_PARAM_I4(frame)      /* x = iteration (1-based), y = frame (1-based), z = seed, w = half-sweep parity (the blend: its pass) */
HD_PARAM_I4(image)      /* x = width, y = height, z = method, w = the path vertex that reads HD's light (0: none, hd_k_path.h) */
HD_PARAM_I4(region)     /* x = the first pixel of the frame's region of the image buffer (0; a
                           reduced frame's: the full image's width * height, hd_k_upsample.h),
                           y = the upsample pass's render scale (0 in every other pass), z = the
                           depth plane's first float in the image buffer (hdk_project_depth), w = the
                           blend planes' first float (HD_REST_BLEND's paths and blend pass; 0 in every
                           other pass); the blend pass has its tile radius in y */
HD_PARAM_F4(box)        /* world size of the volume box (centred at 0); w = 1 / (4 pi) */
HD_PARAM_F4(medium)     /* x = extinction, y = albedo, z = anisotropy g, w = global majorant */
HD_PARAM_F4(grid)       /* xyz = 1 / h^2 of the illumination grid (world), w = sigma' floor */
HD_PARAM_F4(gridh)      /* xyz = h of the illumination grid (world), w = the box's diagonal bound (HD_BOX_DIAGONAL * largest side) */
HD_PARAM_F4(march)      /* x = ray-march step (world), y = frame weight, z = cutoff T, w = the direct light's sample weight */
HD_PARAM_F4(cam_pos)    /* the ray origin at the image centre (all in the volume's frame, hdk_camera_ray) */
HD_PARAM_F4(cam_u)      /* the direction's change per NDC x (look-at: image right * tan(fov/2) * aspect) */
HD_PARAM_F4(cam_v)      /* its change per NDC y (look-at: image up * tan(fov/2)) */
HD_PARAM_F4(cam_w)      /* the direction at the image centre (look-at: forward, unit) */
HD_PARAM_F4(cam_ou)     /* the origin's change per NDC x (orthographic; 0 for a perspective camera) */
HD_PARAM_F4(cam_ov)     /* the origin's change per NDC y */
HD_PARAM_I4(depth_dims) /* the host's depth buffer: x = width, y = height (the full image's), z = 1: on,
                           w = 1: its rows bottom first (a GL depth texture's) */
HD_PARAM_F4(depth_z)    /* NDC z = x * depth + y; z = the far plane's depth (no geometry there);
                           w = 1 - params.depth_threshold (the volume's depth out, hdk_project_depth) */
HD_PARAM_F4(depth_m0)   /* rows 0..3 of the inverse of projection * view, clip to the volume's frame */
HD_PARAM_F4(depth_m1)
HD_PARAM_F4(depth_m2)
HD_PARAM_F4(depth_m3)
HD_PARAM_F4(depth_q)    /* the volume's depth out (hdk_depth_q): the numerator's row over the volume's frame */
HD_PARAM_F4(depth_w)    /* its denominator's row (clip w); all 0 without a matrix camera */
HD_PARAM_F4(background) /* rgb radiance behind the volume; w = 1: the environment shows behind it too
                           (params.environment_background with a map set, hdk_env_background) */
HD_PARAM_F4(chan_color) /* with 1 channel: the lights' common colour, applied at projection */
HD_PARAM_F4(crop_lo)    /* xyz = the crop box's low corner in texture coordinates; w = 1: on */
HD_PARAM_F4(crop_hi)    /* xyz = its high corner */
HD_PARAM_I4(env)        /* the environment (hd_k_light.h): x = width, y = height (0: none), z, w = where
                           its marginal and conditional CDFs start in the env buffer */
HD_PARAM_F4(env_r0)     /* rows of the rotation from the volume's frame into the map's */
HD_PARAM_F4(env_r1)
HD_PARAM_F4(env_r2)
HD_PARAM_I4(vstore)     /* x = the volume's storage (HD_VOL_*), y, z, w = 0 */
HD_PARAM_F4(vnorm)      /* raw voxel to TF coordinate: clamp((raw - x) * y, 0, 1); z, w = 0 */
HD_PARAM_F4_ARRAY(light_a, HD_MAX_LIGHTS) /* xyz = unit travel direction or position (a quad's corner), w = hd_light_type */
HD_PARAM_F4_ARRAY(light_b, HD_MAX_LIGHTS) /* rgb = colour * intensity (x only with 1 channel), w = 1/r^2 */
HD_PARAM_F4_ARRAY(light_c, HD_MAX_LIGHTS) /* area lights: a quad's edge 1 and area, a disk's unit normal and radius, a sphere's radius (w) */
HD_PARAM_F4_ARRAY(light_d, HD_MAX_LIGHTS) /* xyz = a quad's edge 2, a disk's unit tangent; w = the chance of lights 0..l (hdk_light_choose) */
HD_PARAMS_END
