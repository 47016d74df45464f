/*
 * The optional "camera" of "rays": a fixed view for scenes whose automatic
 * framing is not the view a user wants to measure.
 */
#include <math.h>
#include <string.h>

#include "config/config_internal.h"

static const char *const camera_keys[] = { "position", "target", "up", "fov", NULL };

/* A [x, y, z] array of finite numbers into out; absent keeps out. */
static int get_vec3(const struct config *cfg, const cJSON *obj, const char *key, float out[3],
                    bvhlab_error *err)
{
	const cJSON *item = config_member(obj, key);
	char got[48];
	if (!item)
		return 0;
	if (cJSON_IsArray(item) && cJSON_GetArraySize(item) == 3) {
		float v[3];
		int k = 0;
		const cJSON *e;
		cJSON_ArrayForEach(e, item) {
			if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) ||
			    fabs(e->valuedouble) > 1e30)
				break;
			v[k++] = (float)e->valuedouble;
		}
		if (k == 3) {
			memcpy(out, v, sizeof(v));
			return 0;
		}
	}
	return config_error(cfg, item, false, err,
	                    "'rays.camera.%s' must be an array of 3 finite numbers, not %s", key,
	                    config_describe(cfg, item, got, sizeof(got)));
}

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
	int rc = config_check_keys(cfg, cam, camera_keys, "in rays.camera", err);
	if (!rc && !config_member(cam, "position"))
		rc = config_error(cfg, cam, false, err, "'rays.camera' needs a \"position\"");
	if (!rc)
		rc = get_vec3(cfg, cam, "position", cfg->camera.position, err);
	if (!rc)
		rc = get_vec3(cfg, cam, "target", cfg->camera.target, err);
	if (!rc)
		rc = get_vec3(cfg, cam, "up", cfg->camera.up, err);
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
