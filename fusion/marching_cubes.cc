#include "fusion/marching_cubes.h"

#include <pcl/surface/marching_cubes.h>  // The case tables (edgeTable, triTable).

namespace ihs::fusion::marching_cubes {

int EdgeMask(int case_index) { return pcl::edgeTable[case_index]; }

const int* Triangles(int case_index) { return pcl::triTable[case_index]; }

}  // namespace ihs::fusion::marching_cubes
