/* Forwarding header: gmasim_c.h moved to gmasim/capi/gmasim_c.h (issue 21; docs/layers.md, "The
   public headers"). Kept so that existing users still compile; include the new path. */
#ifndef GMASIM_FORWARD_GMASIM_C_H
#define GMASIM_FORWARD_GMASIM_C_H
#include "gmasim/capi/gmasim_c.h"
#endif
