/*
 * boundary.c - velocity constraints on grid faces (000 §4.5 steps 3e, 4d, 6d and the MUSL
 * displacement of step 8a), shared by every scheme.
 *
 * Each face's soil and water constraints are independent of its drainage (pressure.c): a fixed
 * face may be drained. "slip" fixes the normal component (a roller), "fixed" both, "plate" marks
 * the normal component as a wall whose velocity plate.c sets. With the
 * interpolating edge basis of shape.h, a constraint on the edge nodes is exact at the wall.
 */
#include <string.h>

#include "sim_internal.h"

static unsigned char constraint_bits(enum face_constraint c, int normal_bit)
{
	/* a plate's normal component is a wall that moves with the plate (plate.c) */
	return c == CONSTRAINT_FIXED ? 3 : c == CONSTRAINT_SLIP || c == CONSTRAINT_PLATE ? (unsigned char)normal_bit : 0;
}

void boundary_mark(struct sim *s)
{
	const struct grid *g = &s->grid;
	const struct case_boundary *bc = s->spec->boundaries;
	memset(s->f.fix_s, 0, (size_t)g->node_count);
	memset(s->f.fix_w, 0, (size_t)g->node_count);
	for (idx_t j = 0; j < g->nodes[1]; j++)
		for (idx_t i = 0; i < g->nodes[0]; i++) {
			idx_t I = grid_node(g, i, j);
			/* normal bit: 1 = x component for left/right, 2 = y component for bottom/top */
			const struct { int on; enum grid_face face; int bit; } faces[] = {
				{i == 0, FACE_LEFT, 1}, {i == g->cells[0], FACE_RIGHT, 1},
				{j == 0, FACE_BOTTOM, 2}, {j == g->cells[1], FACE_TOP, 2}};
			for (int k = 0; k < 4; k++) {
				if (!faces[k].on)
					continue;
				s->f.fix_s[I] |= constraint_bits(bc[faces[k].face].soil, faces[k].bit);
				s->f.fix_w[I] |= constraint_bits(bc[faces[k].face].water, faces[k].bit);
			}
		}
}

void boundary_apply(const struct grid *g, const unsigned char *fix, double *v)
{
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < g->node_count; I++) {
		if (fix[I] & 1)
			v[2 * I] = 0.0;
		if (fix[I] & 2)
			v[2 * I + 1] = 0.0;
	}
}
