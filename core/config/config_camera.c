/*
 * The optional "camera" of "rays": a fixed view for scenes whose automatic
 * framing is not the view a user wants to measure.
 */
#include <string.h>

#include "config/config_internal.h"

static int check_camera(const struct config *cfg, const cJSON *cam, bvhlab_error *err)
{
	const bvhlab_camera *c = &cfg->camera;
	float d[3] = {c->target[0] - c->position[0], c->target[1] - c->position[1],
	              c->target[2] - c->position[2]};
	float x[3] = {d[1] * c->up[2] - d[2] * c->up[1], d[2] * c->up[0] - d[0] * c->up[2],
	              d[0] * c->up[1] - d[1] * c->up[0]};
	if (d[0] == 0 && d[1] == 0 && d[2] == 0)
		return config_error(cfg, cam, false, err,
		                    "'rays.camera': position and target must differ");
	if (x[0] == 0 && x[1] == 0 && x[2] == 0)
		return config_error(cfg, cam, false, err,
		                    "'rays.camera': up must not be parallel to the view direction");
	return 0;
}

int config_parse_camera(struct config *cfg, const cJSON *rays, bvhlab_error *err)
{
	const cJSON *cam = config_member(rays, "camera");
	char got[48];
	double fov = 45.0;
	if (!cam)
		return 0;
	if (!cJSON_IsObject(cam))
		return config_error(cfg, cam, false, err,
		                    "'rays.camera' must be an object {position, target, up, fov}, "
		                    "not %s", config_describe(cfg, cam, got, sizeof(got)));
	memset(&cfg->camera, 0, sizeof(cfg->camera));
	cfg->camera.up[1] = 1.0f;
	int rc = config_check_keys(cfg, cam, config_camera_keys, "in rays.camera", err);
	if (!rc && !config_member(cam, "position"))
		rc = config_error(cfg, cam, false, err, "'rays.camera' needs a \"position\"");
	if (!rc)
		rc = config_read_keys(cfg, cam, config_camera_keys, "rays.camera.", &cfg->camera,
		                      err);
	if (!rc)
		rc = config_get_positive(cfg, cam, "fov", "rays.camera.", &fov, err);
	if (!rc && fov >= 180.0)
		rc = config_error(cfg, config_member(cam, "fov"), false, err,
		                  "'rays.camera.fov' must be below 180 degrees, not %g", fov);
	if (!rc)
		rc = check_camera(cfg, cam, err);
	cfg->camera.fov_deg = (float)fov;
	cfg->has_camera = rc == 0;
	return rc;
}
