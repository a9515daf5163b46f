/* lucent kernel: perspective camera with vertical field of view and thin-lens depth of field. */
#ifndef LUCENT_CAMERA_CL
#define LUCENT_CAMERA_CL

/* Uniform point on the unit disk (Shirley-Chiu concentric mapping). */
static inline float2 sample_concentric_disk(float u1, float u2) {
  float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
  if (a == 0.0f && b == 0.0f) return (float2)(0.0f, 0.0f);
  /* angles in units of pi: sinpi/cospi need no general range reduction (util/math.cl) */
  float r, phi;
  if (fabs(a) > fabs(b)) {
    r = a;
    phi = 0.25f * (b / a);
  } else {
    r = b;
    phi = 0.5f - 0.25f * (a / b);
  }
  return (float2)(r * cospi(phi), r * sinpi(phi));
}

/* Ray through film position (fx, fy) in pixels, (0,0) = top-left corner of the image. In lc_real
 * from the film position on (--precision double: double origin and direction). */
static inline lc_ray camera_generate_ray(__global const lc_camera* cam, float fx, float fy,
                                         lc_uint width, lc_uint height, float lu, float lv) {
  lc_real ndc_x =
      (LC_REAL(2.0) * fx / (lc_real)width - LC_REAL(1.0)) * cam->tan_half_fov * cam->aspect;
  lc_real ndc_y = (LC_REAL(1.0) - LC_REAL(2.0) * fy / (lc_real)height) * cam->tan_half_fov;
  lc_real3 right = lc_load3r(cam->right), up = lc_load3r(cam->up), fwd = lc_load3r(cam->forward);
  lc_real3 dir = normalize(fwd + ndc_x * right + ndc_y * up);
  lc_ray ray;
  ray.o = lc_load3r(cam->position);
  ray.d = dir;
#ifdef LC_HAS_THIN_LENS
  if (cam->lens_radius > 0.0f) {
    /* the focal plane is perpendicular to the viewing direction at focus_distance: the ray from
     * the lens point position + off aims at position + ft dir, ft = focus_distance / dot(dir,
     * fwd), along ft dir - off, here divided by ft. (ft itself overflowed float where a wide
     * angle met a large focus distance: 1e38 at fov 150 gave the image's corners rays through
     * infinity, without a word. off / focus_distance is at most the aperture's limit, 100.) */
    float2 lens = cam->lens_radius * sample_concentric_disk(lu, lv);
    lc_real3 off = (lc_real)lens.x * right + (lc_real)lens.y * up;
    ray.o = ray.o + off;
    ray.d = normalize(dir - (off / (lc_real)cam->focus_distance) * dot(dir, fwd));
  }
#endif
  return ray;
}

/* The pinhole's film position (fx, fy) of the point position + d (the inverse of
 * camera_generate_ray without a lens; the same for any positive multiple of d) and the cosine
 * between forward and d; 0 when the point is not in front. */
static inline int camera_project_offset(__global const lc_camera* cam, lc_real3 d, lc_uint width,
                                        lc_uint height, float* fx, float* fy, float* cos_c) {
  lc_real z = dot(d, lc_load3r(cam->forward));
  if (!(z > LC_REAL(0.0))) return 0;
  lc_real ndc_x = dot(d, lc_load3r(cam->right)) / (z * cam->tan_half_fov * cam->aspect);
  lc_real ndc_y = dot(d, lc_load3r(cam->up)) / (z * cam->tan_half_fov);
  *fx = (float)((ndc_x + LC_REAL(1.0)) * (LC_REAL(0.5) * (lc_real)width));
  *fy = (float)((LC_REAL(1.0) - ndc_y) * (LC_REAL(0.5) * (lc_real)height));
  *cos_c = (float)(z / length(d));
  return 1;
}

/* camera_project_offset of point p */
static inline int camera_project(__global const lc_camera* cam, lc_real3 p, lc_uint width,
                                 lc_uint height, float* fx, float* fy, float* cos_c) {
  return camera_project_offset(cam, p - lc_load3r(cam->position), width, height, fx, fy, cos_c);
}

/* Light tracing's connection to the camera: the point *o of the lens that the connection to p
 * starts from (the lens point (lu, lv) mapped as camera_generate_ray maps it; the pinhole's
 * position without a lens), the film position (fx, fy) of the camera rays from *o that reach p
 * (through the point of the focal plane on the line from *o through p) and the cosine between
 * forward and p - *o; 0 when p is not in front of *o. */
static inline int camera_project_lens(__global const lc_camera* cam, lc_real3 p, float lu, float lv,
                                      lc_uint width, lc_uint height, float* fx, float* fy,
                                      float* cos_c, lc_real3* o) {
  *o = lc_load3r(cam->position);
#ifdef LC_HAS_THIN_LENS
  if (cam->lens_radius > 0.0f) {
    lc_real3 right = lc_load3r(cam->right), up = lc_load3r(cam->up);
    float2 lens = cam->lens_radius * sample_concentric_disk(lu, lv);
    lc_real3 off = (lc_real)lens.x * right + (lc_real)lens.y * up;
    *o += off;
    lc_real3 d = p - *o;
    lc_real z = dot(d, lc_load3r(cam->forward));
    if (!(z > LC_REAL(0.0))) return 0;
    /* camera_generate_ray aims every lens point of a film position at the focal plane's point
     * that the film position's pinhole ray crosses: the film position is the pinhole's of the
     * focal plane's point on the line from *o through p, position + off + d focus_distance / z,
     * here times z / focus_distance (the point itself overflowed float for a point near the
     * lens plane with a large focus distance) */
    float unused;
    if (!camera_project_offset(cam, d + (off / (lc_real)cam->focus_distance) * z, width, height, fx,
                               fy, &unused))
      return 0;
    *cos_c = (float)(z / length(d));
    return 1;
  }
#endif
  return camera_project(cam, p, width, height, fx, fy, cos_c);
}

#endif
