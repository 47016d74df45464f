/*
 * The optional "camera" of "rays", and a scene's own "camera": a fixed view
 * for scenes whose automatic framing is not the view a user wants to
 * measure (a room seen from inside, as papers render architecture). A
 * scene's camera wins over the one of "rays" for that scene.
 */
#include <stdio.h>
#include <string.h>

#include "config/config_internal.h"

static int check_camera(const struct config *cfg, const cJSON *cam, const bvhlab_camera *c,
                        const char *where, bvhlab_error *err)
{
	float d[3] = {c->target[0] - c->position[0], c->target[1] - c->position[1],
	              c->target[2] - c->position[2]};
	float x[3] = {d[1] * c->up[2] - d[2] * c->up[1], d[2] * c->up[0] - d[0] * c->up[2],
	              d[0] * c->up[1] - d[1] * c->up[0]};
	if (d[0] == 0 && d[1] == 0 && d[2] == 0)
		return config_error(cfg, cam, false, err,
		                    "'%s': position and target must differ", where);
	if (x[0] == 0 && x[1] == 0 && x[2] == 0)
		return config_error(cfg, cam, false, err,
		                    "'%s': up must not be parallel to the view direction", where);
	return 0;
}

/* The camera object `cam`, named `where` in messages ("rays.camera",
 * "scenes[2].camera"), into *out. */
static int parse_camera(const struct config *cfg, const cJSON *cam, const char *where,
                        bvhlab_camera *out, bvhlab_error *err)
{
	char got[48], in[80], prefix[80];
	double fov = 45.0;
	if (!cJSON_IsObject(cam))
		return config_error(cfg, cam, false, err,
		                    "'%s' must be an object {position, target, up, fov}, not %s",
		                    where, config_describe(cfg, cam, got, sizeof(got)));
	snprintf(in, sizeof(in), "in %s", where);
	snprintf(prefix, sizeof(prefix), "%s.", where);
	memset(out, 0, sizeof(*out));
	out->up[1] = 1.0f;
	int rc = config_check_keys(cfg, cam, config_camera_keys, in, err);
	if (!rc && !config_member(cam, "position"))
		rc = config_error(cfg, cam, false, err, "'%s' needs a \"position\"", where);
	if (!rc)
		rc = config_read_keys(cfg, cam, config_camera_keys, prefix, out, err);
	if (!rc)
		rc = config_get_positive(cfg, cam, "fov", prefix, &fov, err);
	if (!rc && fov >= 180.0)
		rc = config_error(cfg, config_member(cam, "fov"), false, err,
		                  "'%s.fov' must be below 180 degrees, not %g", where, fov);
	if (!rc)
		rc = check_camera(cfg, cam, out, where, err);
	out->fov_deg = (float)fov;
	return rc;
}

int config_parse_camera(struct config *cfg, const cJSON *rays, bvhlab_error *err)
{
	const cJSON *cam = config_member(rays, "camera");
	if (!cam)
		return 0;
	int rc = parse_camera(cfg, cam, "rays.camera", &cfg->camera, err);
	cfg->has_camera = rc == 0;
	return rc;
}

int config_parse_scene_camera(const struct config *cfg, const cJSON *scene, size_t index,
                              struct config_scene *sc, bvhlab_error *err)
{
	const cJSON *cam = config_member(scene, "camera");
	char where[48];
	if (!cam)
		return 0;
	snprintf(where, sizeof(where), "scenes[%zu].camera", index);
	int rc = parse_camera(cfg, cam, where, &sc->camera, err);
	sc->has_camera = rc == 0;
	return rc;
}
