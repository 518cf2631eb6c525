// A small loader for libsdformat (no Python binding installs here): load an SDF file, print every error and
// the model's links, masses, collisions and plugins. Built by tests/test_gazebo_exports.py with g++ and pkg-config.
#include <sdf/sdf.hh>
#include <iostream>
int main(int argc, char** argv) {
  if (argc < 2) { std::cerr << "usage: sdf_check FILE\n"; return 2; }
  sdf::Root root;
  sdf::Errors errors = root.Load(argv[1]);
  for (const auto& e : errors) std::cout << "error: " << e << "\n";
  if (!errors.empty()) return 1;
  const sdf::Model* m = root.Model();
  if (m) {
    std::cout << "model " << m->Name() << " links " << m->LinkCount() << " joints " << m->JointCount() << "\n";
    for (uint64_t i = 0; i < m->LinkCount(); ++i) {
      const sdf::Link* l = m->LinkByIndex(i);
      std::cout << "link " << l->Name() << " mass " << l->Inertial().MassMatrix().Mass() << " collisions " << l->CollisionCount() << "\n";
    }
    auto el = m->Element();
    int plugins = 0;
    if (el->HasElement("plugin")) for (auto p = el->GetElement("plugin"); p; p = p->GetNextElement("plugin")) ++plugins;
    std::cout << "plugins " << plugins << "\n";
  }
  for (uint64_t w = 0; w < root.WorldCount(); ++w) std::cout << "world " << root.WorldByIndex(w)->Name() << " models " << root.WorldByIndex(w)->ModelCount() << "\n";
  return 0;
}
