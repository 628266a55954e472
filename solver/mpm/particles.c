/* particles.c - allocation of a material point set (see particles.h). */
#include "particles.h"

#include <stdlib.h>
#include <string.h>

#include "point_blocks.h"

/* Every owned array, with its per-point width, in one table so init and release cannot drift. */
#define PARTICLE_ARRAYS(X, skel)                                   \
	X(x, 2, !alias) X(x0, 2, !alias) X(v, 2, 1) X(mass, 1, 1)  \
	X(volume, 1, !alias) X(volume0, 1, !alias)                 \
	X(porosity, 1, !alias) X(porosity0, 1, !alias)             \
	X(conductivity, 1, !alias) X(pressure, 1, 1)               \
	X(stress, 4, skel) X(F, 4, skel) X(Be, 4, skel)            \
	X(state, STATE_MAX, skel) X(plastic_strain, 1, skel)       \
	X(dF, 4, skel) X(surface, 2, skel)                         \
	X(shape, 4 * SHAPE_SUPPORT_MAX, !alias)                    \
	X(C, 4, 0) X(dF_zz, 1, 0) X(acceleration, 2, 0) \
	/* allocated on request: particles_add_affine, _out_of_plane, _implicit_state */

static enum poro_status allocate(struct particles *p, idx_t n, int skel, int alias, struct poro_error *err)
{
	memset(p, 0, sizeof *p);
	p->n = n;
	size_t count = n > 0 ? (size_t)n : 1;
	int ok = 1;
#define ALLOC(name, width, wanted) \
	if ((wanted) && ok) ok = (p->name = calloc(count * (width), sizeof(double))) != NULL;
	PARTICLE_ARRAYS(ALLOC, skel)
#undef ALLOC
	if (ok && !alias) {
		ok = (p->body = calloc(count, sizeof(int))) && (p->node0 = calloc(count, sizeof(idx_t)));
	}
	if (ok && skel)
		ok = (p->surface_load = calloc(count, sizeof(int))) != NULL;
	if (!ok) {
		particles_release(p);
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate %ld material points", (long)n);
	}
	if (skel)
		for (idx_t i = 0; i < n; i++)
			p->surface_load[i] = -1;
	return PORO_OK;
}

enum poro_status particles_init(struct particles *p, idx_t n, int with_skeleton, struct poro_error *err)
{
	return allocate(p, n, with_skeleton, 0, err);
}

enum poro_status particles_init_alias(struct particles *w, const struct particles *soil, struct poro_error *err)
{
	enum poro_status st = allocate(w, soil->n, 0, 1, err);
	if (st)
		return st;
	w->alias_of = soil;
	w->x = soil->x;
	w->x0 = soil->x0;
	w->volume = soil->volume;
	w->volume0 = soil->volume0;
	w->porosity = soil->porosity;
	w->porosity0 = soil->porosity0;
	w->conductivity = soil->conductivity;
	w->body = soil->body;
	w->node0 = soil->node0;
	w->shape = soil->shape;
	w->support = soil->support;
	return PORO_OK;
}

enum poro_status particles_add_affine(struct particles *p, struct poro_error *err)
{
	if (!p->C && !(p->C = calloc((p->n > 0 ? (size_t)p->n : 1) * 4, sizeof(double))))
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the affine velocities of %ld points",
				      (long)p->n);
	return PORO_OK;
}

enum poro_status particles_add_blocks(struct particles *p, const struct grid *g, struct poro_error *err)
{
	static const idx_t size[2] = {POINT_BLOCK_CELLS_X, POINT_BLOCK_CELLS_Y};
	return p->blocks ? PORO_OK : point_blocks_create(&p->blocks, g, p->n, size, err);
}

enum poro_status particles_add_out_of_plane(struct particles *p, struct poro_error *err)
{
	if (!p->dF_zz && !(p->dF_zz = calloc(p->n > 0 ? (size_t)p->n : 1, sizeof(double))))
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the out-of-plane stretches of %ld points",
				      (long)p->n);
	return PORO_OK;
}

enum poro_status particles_add_implicit_state(struct particles *p, struct poro_error *err)
{
	const size_t n = p->n > 0 ? (size_t)p->n : 1;
	if (!p->acceleration && !(p->acceleration = calloc(2 * n, sizeof(double))))
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the implicit state of %ld points", (long)p->n);
	return PORO_OK;
}

void particles_remove(struct particles *p, idx_t q)
{
	idx_t last = p->n - 1;
	if (q != last) {
#define MOVE(name, width, wanted) \
		if (p->name) memcpy(p->name + (size_t)q * (width), p->name + (size_t)last * (width), sizeof(double) * (width));
		PARTICLE_ARRAYS(MOVE, 0)
#undef MOVE
		p->body[q] = p->body[last];
		p->node0[q] = p->node0[last];
	}
	p->n--;
	if (p->blocks)
		p->blocks->n = -1;
}

void particles_release(struct particles *p)
{
	if (!p)
		return;
	if (!p->alias_of) {
		free(p->x); free(p->x0); free(p->volume); free(p->volume0);
		free(p->porosity); free(p->porosity0); free(p->conductivity);
		free(p->shape); free(p->body); free(p->node0);
	}
	free(p->v); free(p->C); free(p->mass); free(p->pressure);
	free(p->stress); free(p->F); free(p->Be); free(p->state); free(p->plastic_strain);
	free(p->dF); free(p->dF_zz); free(p->acceleration);
	free(p->surface); free(p->surface_load);
	point_blocks_destroy(&p->blocks);
	memset(p, 0, sizeof *p);
}
