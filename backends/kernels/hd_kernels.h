/* hd_kernels.h - the shared kernel sources in dependency order, for the C backend. The GPU
   backends embed the same files as strings behind their own prelude (see amalgamate). */
#include "hd_k_common.h"
#include "hd_k_light.h"
#include "hd_k_classify.h"
#include "hd_k_direct.h"
#include "hd_k_diffuse.h"
#include "hd_k_multigrid.h"
#include "hd_k_project.h"
#include "hd_k_upsample.h"
#include "hd_k_convect.h"
#include "hd_k_path.h"
