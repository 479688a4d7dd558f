/* The STM32F405 board image's own parameters (board_app_cfg.h). */
#include "cmd.h"
#include "drv8301.h"
#include "f405_app.h"

/* The board_app_t the link passes is the first member of the f405_t. */
static f405_t *f405_of(void *ctx)
{
    return (f405_t *)ctx;
}

int f405_get_trip(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    *v = (double)f4_hal_trip_cause(&f405_of(ctx)->hal);
    return CMD_OK;
}

int f405_get_drv_status(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    *v = (double)f405_of(ctx)->hal.drv.status[0];
    return CMD_OK;
}

int f405_get_drv_vds(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    *v = (double)drv8301_vds_mv(f405_of(ctx)->board->drv.oc_adj);
    return CMD_OK;
}
