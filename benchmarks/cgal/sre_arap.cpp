// CGAL's Surface_mesh_deformation with the SRE_ARAP tag (smooth-rotation ARAP), as a whole
// process: read an OFF mesh and a constraint file, deform for a fixed number of iterations,
// write an OFF mesh. Built by benchmarks/cgal_sre_arap.py where CGAL's headers are installed
// (Debian: libcgal-dev libeigen3-dev); never part of srarap itself (CGAL is GPL/LGPL).
//
// usage: sre_arap MESH.off CONSTRAINTS.txt OUT.off ITERATIONS [ALPHA]
// CONSTRAINTS.txt: one line per constrained vertex, "id x y z" (0-based id, target position);
// every vertex is in the region of interest, the constrained ones are its control vertices.
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_deformation.h>

#include <cstdlib>
#include <fstream>
#include <iostream>

typedef CGAL::Simple_cartesian<double> Kernel;
typedef CGAL::Surface_mesh<Kernel::Point_3> Mesh;
typedef boost::graph_traits<Mesh>::vertex_descriptor Vertex;
typedef CGAL::Surface_mesh_deformation<Mesh, CGAL::Default, CGAL::Default, CGAL::SRE_ARAP>
    Deformation;

int main(int argc, char** argv) {
  if (argc < 5) {
    std::cerr << "usage: sre_arap MESH.off CONSTRAINTS.txt OUT.off ITERATIONS [ALPHA]\n";
    return 2;
  }
  Mesh mesh;
  std::ifstream in(argv[1]);
  if (!(in >> mesh)) {
    std::cerr << argv[1] << ": not a readable OFF mesh\n";
    return 1;
  }
  Deformation deformation(mesh);
  deformation.insert_roi_vertices(vertices(mesh).begin(), vertices(mesh).end());
  std::ifstream constraints(argv[2]);
  std::size_t id;
  double x, y, z;
  std::vector<std::pair<Vertex, Kernel::Point_3>> targets;
  while (constraints >> id >> x >> y >> z) {
    Vertex v(static_cast<Mesh::size_type>(id));
    deformation.insert_control_vertex(v);
    targets.emplace_back(v, Kernel::Point_3(x, y, z));
  }
  if (argc > 5) deformation.set_sre_arap_alpha(std::atof(argv[5]));
  if (!deformation.preprocess()) {
    std::cerr << "preprocess failed\n";
    return 1;
  }
  for (const auto& t : targets) deformation.set_target_position(t.first, t.second);
  deformation.deform(static_cast<unsigned int>(std::atoi(argv[4])), 0.0);
  std::ofstream out(argv[3]);
  out.precision(17);
  out << mesh;
  return 0;
}
