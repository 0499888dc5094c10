// Loading surfaces in every supported format, and the errors broken files of each kind must give.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "rtcore/mesh/mesh_io.h"
#include "rtcore/mesh/mesh_validation.h"

namespace resecto {
namespace {

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("resecto_mesh_files_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

std::filesystem::path write_file(const std::string& name, const std::string& text) {
  const auto path = scratch(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A unit cube (millimetres), 12 triangles, outward.
const char* kCubeVertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n";
const int kCubeFaces[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                               {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};

std::string cube_off(int skip_face = -1, int flip_face = -1) {
  std::string text = "OFF\n8 " + std::to_string(skip_face >= 0 ? 11 : 12) + " 0\n" + kCubeVertices;
  for (int f = 0; f < 12; ++f) {
    if (f == skip_face) continue;
    const int* t = kCubeFaces[f];
    text += f == flip_face ? "3 " + std::to_string(t[0]) + " " + std::to_string(t[2]) + " " + std::to_string(t[1]) + "\n"
                           : "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  }
  return text;
}

std::string validation_error(const std::filesystem::path& path) {
  Result<TriangleMesh> mesh = read_surface_mesh(path);
  if (!mesh) return mesh.error();
  Result<SurfaceReport> report = validate_closed_surface(*mesh);
  return report ? std::string() : report.error();
}

TEST(MeshFiles, ReadsAValidCubeInEveryFormat) {
  std::string obj, ply = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
                         "element face 12\nproperty list uchar int vertex_indices\nend_header\n";
  obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
  ply += kCubeVertices;
  std::string stl = "solid cube\n";
  const double corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (const auto& t : kCubeFaces) {
    obj += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
    ply += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
    stl += "facet normal 0 0 0\nouter loop\n";
    for (int c = 0; c < 3; ++c) {
      stl += "vertex " + std::to_string(corner[t[c]][0]) + " " + std::to_string(corner[t[c]][1]) + " " + std::to_string(corner[t[c]][2]) + "\n";
    }
    stl += "endloop\nendfacet\n";
  }
  stl += "endsolid cube\n";
  // Each with its lines ended by LF, CR LF and a lone CR (classic Mac OS exporters; audit 30, F6).
  const auto line_ends = [](std::string text, const std::string& end) {
    std::string out;
    for (char c : text) {
      if (c == '\n') out.append(end);
      else out.push_back(c);
    }
    return out;
  };
  for (const auto& [name, lf] : {std::pair{"cube.off", cube_off()}, std::pair{"cube.obj", obj}, std::pair{"cube.ply", ply},
                                 std::pair{"cube.stl", stl}})
  for (const std::string end : {"\n", "\r\n", "\r"}) {
    SCOPED_TRACE(std::string(name) + (end == "\n" ? " LF" : end == "\r" ? " CR" : " CR LF"));
    Result<TriangleMesh> mesh = read_surface_mesh(write_file(name, line_ends(lf, end)));
    ASSERT_TRUE(mesh) << mesh.error();
    EXPECT_EQ(mesh->triangle_count(), 12u);
    Result<SurfaceReport> report = validate_closed_surface(*mesh);
    ASSERT_TRUE(report) << report.error();
    EXPECT_EQ(report->genus, 0);
    EXPECT_NEAR(report->volume_m3, 1e-9, 1e-15);  // 1 mm^3
  }
}

// ASCII STL's keywords in capitals, as older CAD exporters write them, read as the lowercase ones: they
// were taken for a binary STL declaring 774910240 triangles (audit 25, F4).
TEST(MeshFiles, AsciiStlKeywordsInAnyCase) {
  std::string stl = "SOLID CUBE\n";
  const double corners[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (const auto& t : kCubeFaces) {
    stl += " Facet Normal 0 0 0\n  OUTER LOOP\n";
    for (int c = 0; c < 3; ++c) {
      const double* p = corners[t[c]];
      stl += "   VERTEX " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
    }
    stl += "  ENDLOOP\n ENDFACET\n";
  }
  stl += "ENDSOLID CUBE\n";
  Result<TriangleMesh> mesh = read_surface_mesh(write_file("upper.stl", stl));
  ASSERT_TRUE(mesh) << mesh.error();
  EXPECT_EQ(mesh->triangle_count(), 12u);
  EXPECT_TRUE(validate_closed_surface(*mesh));
}

TEST(MeshFiles, PolygonsAreFanTriangulatedInFileOrder) {
  const auto path = write_file("quads.off",
                               "OFF\n8 6 0\n" + std::string(kCubeVertices) +
                                   "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n");
  Result<TriangleMesh> mesh = read_surface_mesh(path);
  ASSERT_TRUE(mesh) << mesh.error();
  ASSERT_EQ(mesh->triangle_count(), 12u);
  EXPECT_EQ(mesh->triangles[0], (Triangle{0, 3, 2}));
  EXPECT_EQ(mesh->triangles[1], (Triangle{0, 2, 1}));
  EXPECT_EQ(mesh->triangles[2], (Triangle{4, 5, 6}));
  EXPECT_TRUE(validate_closed_surface(*mesh));
}

// A polygon file's errors name the file's faces: its triangles (fans, in file order) were named as
// faces, "face 9" of a 6-face file (audit 25, F3).
TEST(MeshFiles, PolygonErrorsNameTheFilesFaces) {
  const std::string corners = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n";
  // The cube as six quads, the fifth reversed.
  const std::string quads = "OFF\n8 6 0\n" + corners + "4 0 1 3 2\n4 4 6 7 5\n4 0 4 5 1\n4 2 3 7 6\n4 4 6 2 0\n4 1 5 7 3\n";
  const std::string error = validation_error(write_file("quads.off", quads));
  EXPECT_NE(error.find("inconsistent orientation"), std::string::npos) << error;
  EXPECT_NE(error.find("face 4 (its fan triangle "), std::string::npos) << error;
  // An L-shaped cap, not convex from its first corner: its own fan crosses itself.
  // (Its cap walks 5 4 3 2 1 0: the fan around corner 5 leaves the L.)
  const std::string prism = "OFF\n12 8 0\n10.0 3.0 0.0\n3.0 3.0 0.0\n3.0 10.0 0.0\n0.0 10.0 0.0\n0.0 0.0 0.0\n10.0 0.0 0.0\n10.0 3.0 5.0\n3.0 3.0 5.0\n3.0 10.0 5.0\n0.0 10.0 5.0\n0.0 0.0 5.0\n10.0 0.0 5.0\n6 5 4 3 2 1 0\n6 6 7 8 9 10 11\n4 0 1 7 6\n4 1 2 8 7\n4 2 3 9 8\n4 3 4 10 9\n4 4 5 11 10\n4 5 0 6 11\n";
  const std::string crossing = validation_error(write_file("lprism.off", prism));
  EXPECT_NE(crossing.find("its fan triangulation (around its first corner) crosses itself"), std::string::npos) << crossing;
}

TEST(MeshFiles, ObjStatementsContinueOverLinesEndingInABackslash) {
  // The format's continuation, as some exporters wrap long faces: the same cube as on single lines.
  std::string obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 \\\n  1\nv 1 1 1\nv 0 1 1\n";
  for (const auto& t : kCubeFaces) {
    obj += "f " + std::to_string(t[0] + 1) + " \\  \r\n" + std::to_string(t[1] + 1) + " \\\n" + std::to_string(t[2] + 1) + "\n";
  }
  Result<TriangleMesh> mesh = read_surface_mesh(write_file("continued.obj", obj));
  ASSERT_TRUE(mesh) << mesh.error();
  ASSERT_EQ(mesh->triangle_count(), 12u);
  EXPECT_EQ(mesh->triangles[0], (Triangle{0, 2, 1}));
  EXPECT_EQ(mesh->positions[5], Vec3(1e-3, 0.0, 1e-3));
  EXPECT_TRUE(validate_closed_surface(*mesh));
  // A comment ending in a backslash continues nothing; an error in a joined statement names its last line.
  EXPECT_TRUE(read_surface_mesh(write_file("comment.obj", "# C:\\meshes\\\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")));
  const std::string error = validation_error(write_file("broken.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 \\\n2 x\n"));
  EXPECT_NE(error.find("broken.obj:5: corner 'x' is not a vertex index"), std::string::npos) << error;
}

TEST(MeshFiles, OpenSurfaceNamesTheEdgeAndFace) {
  const std::string error = validation_error(write_file("open.off", cube_off(/*skip_face=*/5)));
  EXPECT_NE(error.find("open surface"), std::string::npos) << error;
  // Face 5 (0, 5, 4) is missing; of its neighbours, face 2 across (4, 5) comes first in the file.
  EXPECT_NE(error.find("edge (4, 5) of face 2"), std::string::npos) << error;
}

// A "triangle soup" (every face with its own three corners, as some exporters write OFF, OBJ and PLY)
// reads as a surface of loose faces: the open-surface error says why and what to do (audit 30, F9).
TEST(MeshFiles, ATriangleSoupIsNamedAsOne) {
  const char* corner[8] = {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"};
  std::string soup = "OFF\n36 12 0\n", faces;
  for (int f = 0; f < 12; ++f) {
    for (int c = 0; c < 3; ++c) soup += std::string(corner[kCubeFaces[f][c]]) + "\n";
    faces += "3 " + std::to_string(3 * f) + " " + std::to_string(3 * f + 1) + " " + std::to_string(3 * f + 2) + "\n";
  }
  const std::string error = validation_error(write_file("soup.off", soup + faces));
  EXPECT_NE(error.find("open surface"), std::string::npos) << error;
  EXPECT_NE(error.find("; 28 vertices repeat the coordinates of another"), std::string::npos) << error;
  EXPECT_NE(error.find("(a triangle soup): merge coincident vertices"), std::string::npos) << error;
  // An open surface without repeated corners says nothing of soups.
  EXPECT_EQ(validation_error(write_file("open_cube.off", cube_off(5))).find("soup"), std::string::npos);
}

TEST(MeshFiles, FlippedFaceIsInconsistentOrientation) {
  const std::string error = validation_error(write_file("flipped.off", cube_off(-1, /*flip_face=*/7)));
  EXPECT_NE(error.find("inconsistent orientation"), std::string::npos) << error;
  EXPECT_NE(error.find("face 7"), std::string::npos) << error;
}

TEST(MeshFiles, InwardSurfaceIsRejected) {
  std::string text = "OFF\n8 12 0\n" + std::string(kCubeVertices);
  for (const auto& t : kCubeFaces) text += "3 " + std::to_string(t[0]) + " " + std::to_string(t[2]) + " " + std::to_string(t[1]) + "\n";
  const std::string error = validation_error(write_file("inward.off", text));
  EXPECT_NE(error.find("inward orientation"), std::string::npos) << error;
  EXPECT_NE(error.find("face 0"), std::string::npos) << error;
}

// A small solid far from the origin (a part in scanner coordinates): the volume used to be summed
// about the world origin, where its terms cancel; a correct 1 mm cube at 999000 mm read as inward,
// and a 10 mm one as 1.05 ml (audit 25, F1).
TEST(MeshFiles, VolumeAndOrientationHoldFarFromTheOrigin) {
  const auto cube_at = [](double side, double offset, bool inward) {
    std::string text = "OFF\n8 12 0\n";
    for (int v = 0; v < 8; ++v) {
      const int x = (v == 1 || v == 2 || v == 5 || v == 6), y = (v == 2 || v == 3 || v == 6 || v == 7), z = v >= 4;
      text += std::to_string(offset + side * x) + " " + std::to_string(offset + side * y) + " " + std::to_string(offset + side * z) + "\n";
    }
    for (const auto& t : kCubeFaces) {
      text += "3 " + std::to_string(t[0]) + " " + std::to_string(inward ? t[2] : t[1]) + " " + std::to_string(inward ? t[1] : t[2]) + "\n";
    }
    return text;
  };
  for (const double offset : {0.0, 300000.0, 999000.0}) {
    SCOPED_TRACE(offset);
    for (const double side : {1.0, 10.0}) {
      Result<TriangleMesh> mesh = read_surface_mesh(write_file("far.off", cube_at(side, offset, false)));
      ASSERT_TRUE(mesh) << mesh.error();
      Result<SurfaceReport> report = validate_closed_surface(*mesh);
      ASSERT_TRUE(report) << report.error();
      const double volume_m3 = side * side * side * 1e-9;
      EXPECT_NEAR(report->volume_m3, volume_m3, 1e-9 * volume_m3);
      EXPECT_NE(validation_error(write_file("far_inward.off", cube_at(side, offset, true))).find("inward orientation"), std::string::npos);
    }
  }
}

TEST(MeshFiles, NonManifoldEdgeNamesTheFaces) {
  // A cube plus a fin: an extra triangle on the cube's edge (0, 1) makes that edge three-way.
  std::string text = "OFF\n9 13 0\n" + std::string(kCubeVertices) + "0.5 -1 -1\n";
  for (const auto& t : kCubeFaces) text += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  text += "3 0 1 8\n3 1 0 8\n";  // two fins: the edge is shared by four faces, and each is named
  const std::string error = validation_error(write_file("fin.ply", std::string("ply\nformat ascii 1.0\nelement vertex 9\nproperty float x\n"
      "property float y\nproperty float z\nelement face 14\nproperty list uchar int vertex_indices\nend_header\n") +
      text.substr(text.find('\n', 4) + 1)));
  EXPECT_NE(error.find("non-manifold edge (0, 1) is shared by 4 faces (face 0, "), std::string::npos) << error;
  EXPECT_NE(error.find(", 12, 13)"), std::string::npos) << error;
}

TEST(MeshFiles, BowtieVertexIsNonManifold) {
  // Two tetrahedra sharing only vertex 0.
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv -1 0 0\nv 0 -1 0\nv 0 0 -1\n"
      "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
      "f 1 6 5\nf 1 5 7\nf 1 7 6\nf 5 6 7\n";
  const std::string error = validation_error(write_file("bowtie.obj", obj));
  EXPECT_NE(error.find("non-manifold vertex 0 at (0, 0, 0) mm"), std::string::npos) << error;
}

// An STL file numbers no vertices (the reader numbers the merged corners in order of first
// appearance), so an error about an edge says where the edge is, in the file's millimetres.
TEST(MeshFiles, OpenStlSurfaceNamesWhereTheEdgeIs) {
  const std::string stl =
      "solid open\n"
      "facet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 10 0\nvertex 10 0 0\nendloop\nendfacet\n"
      "facet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 10 0 0\nvertex 0 0 10\nendloop\nendfacet\n"
      "facet normal -1 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 10\nvertex 0 10 0\nendloop\nendfacet\n"
      "endsolid open\n";
  const std::string error = validation_error(write_file("open.stl", stl));
  EXPECT_NE(error.find("open surface: edge (1, 2) of face 0 has no neighbouring face; the edge runs from (0, 10, 0) to (10, 0, 0) mm"),
            std::string::npos)
      << error;
}

TEST(MeshFiles, DegenerateTriangleIsNamed) {
  // The cube with vertex 2 moved onto the edge from 0 to 1: face 0 (0, 2, 1) collapses to a segment.
  std::string text = cube_off();
  text.replace(text.find("1 1 0\n"), 6, "0.5 0 0\n");
  const std::string error = validation_error(write_file("degenerate.off", text));
  EXPECT_NE(error.find("degenerate triangle: face 0"), std::string::npos) << error;
}

TEST(MeshFiles, SelfIntersectionNamesBothFaces) {
  // Two closed tetrahedra, the second pushed through the first.
  const std::string off =
      "OFF\n8 8 0\n0 0 0\n2 0 0\n0 2 0\n0 0 2\n0.2 0.2 0.2\n3 0.2 0.2\n0.2 3 0.2\n0.2 0.2 3\n"
      "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n3 4 6 5\n3 4 5 7\n3 4 7 6\n3 5 6 7\n";
  const std::string error = validation_error(write_file("crossing.off", off));
  EXPECT_NE(error.find("self-intersection: face 3 crosses face"), std::string::npos) << error;
}

TEST(MeshFiles, BadIndexAndBadFilesAreNamed) {
  EXPECT_NE(validation_error(write_file("badindex.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")).find("badindex.off"),
            std::string::npos);
  EXPECT_NE(validation_error(write_file("empty.stl", "")).find("empty"), std::string::npos);
  EXPECT_NE(validation_error(write_file("garbage.ply", "this is not a mesh\n")).find("garbage.ply"), std::string::npos);
  EXPECT_NE(validation_error(scratch("missing.obj")).find("no such file"), std::string::npos);
  EXPECT_NE(validation_error(write_file("mesh.xyz", "1 2 3\n")).find("unsupported"), std::string::npos);
}

TEST(MeshFiles, MalformedWordsAreNamedForWhatTheyAre) {
  // Each once gave a wrong or cut-off message, or was read silently.
  const std::string cube = cube_off();
  std::string with_nul = cube;
  with_nul.insert(with_nul.find("1 1 1\n") + 5, std::string(1, '\0'));
  EXPECT_NE(validation_error(write_file("nul.off", with_nul)).find("'1\\x00' is not a number"), std::string::npos)
      << "the NUL printed, not cutting the message";
  std::string fractional = cube;
  fractional.replace(fractional.find("3 1 6 5"), 7, "3 1 6.0 5");
  EXPECT_NE(validation_error(write_file("fraction.off", fractional)).find("vertex index '6.0' is not a whole number"), std::string::npos);
  std::string obj;
  for (const char* v : {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"}) obj += std::string("v ") + v + "\n";
  for (const auto& t : kCubeFaces) obj += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
  for (const char* corner : {"1/x/3", "1/2/3/4", "1/", "1//"}) {
    std::string bad = obj;
    bad.replace(bad.find("f 1 3 2"), 7, std::string("f ") + corner + " 3 2");
    EXPECT_NE(validation_error(write_file("corner.obj", bad)).find("is not a vertex index (v, v/vt, v//vn or v/vt/vn)"), std::string::npos) << corner;
  }
  std::string forms = obj;
  forms.replace(forms.find("f 1 3 2"), 7, "f 1/1/1 3//2 2/5");
  EXPECT_EQ(validation_error(write_file("forms.obj", forms)), "");
  std::string five = obj;
  five.replace(0, 7, "v 0 0 0 1 1");
  EXPECT_NE(validation_error(write_file("five.obj", five)).find("found 5 numbers"), std::string::npos);
  std::string ply = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\nelement face 12\n"
                    "property list uchar int vertex_indices\nend_header\n";
  for (const char* v : {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"}) ply += std::string(v) + " 7\n";
  for (const auto& t : kCubeFaces) ply += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  EXPECT_NE(validation_error(write_file("extra.ply", ply)).find("vertex 0 has a value past its 3 properties: '7'"), std::string::npos);
}

// Audit 6, B: "0x1p3", "1.0mm" and "1,5" were each called "not a finite number", which reads as an
// overflow; they are no number at all. NaN, infinity and overflow stay "not a finite number".
TEST(MeshFiles, WordsThatAreNoNumberAreToldFromNonFiniteOnes) {
  const std::string cube = cube_off();
  const std::pair<const char*, const char*> words[] = {{"0x1p3", "is not a number"},       {"1.0mm", "is not a number"},
                                                       {"1,5", "is not a number"},         {"nan", "is not a finite number"},
                                                       {"-inf", "is not a finite number"}, {"1e999", "is not a finite number"}};
  for (const auto& [word, says] : words) {
    std::string bad = cube;
    bad.replace(bad.find("1 1 1\n"), 1, word);
    EXPECT_EQ(validation_error(write_file("word.off", bad)), scratch("word.off").string() + ":9:1: '" + word + "' " + says) << word;
  }
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 0\n"
      "property list uchar int vertex_indices\nend_header\n";
  EXPECT_NE(validation_error(write_file("word.ply", ply + "1.0mm 0 0\n")).find("vertex 0 x '1.0mm' is not a number"), std::string::npos);
  EXPECT_NE(validation_error(write_file("word.ply", ply + "inf 0 0\n")).find("vertex 0 x 'inf' is not a finite number"), std::string::npos);
}

// Audit 6, B: a second `property float x` silently replaced the first column, and the file failed
// later as a degenerate triangle on some face.
TEST(MeshFiles, APlyPropertyDeclaredTwiceInAnElementIsRefused) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\nproperty float x\n"
      "element face 12\nproperty list uchar int vertex_indices\nend_header\n";
  EXPECT_EQ(validation_error(write_file("twice.ply", header)),
            scratch("twice.ply").string() + ":7:16: element 'vertex' declares property 'x' twice (first on line 4)");
  // The same name in two elements is two properties.
  const std::string apart =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nproperty float x\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 5\n";
  const Result<TriangleMesh> read = read_surface_mesh(write_file("apart.ply", apart));
  EXPECT_TRUE(read) << read.error();
}

// Audit 32, F14: some exporters write only the vertex and face counts ("8 12"); the edge count no
// reader uses was then read from the first vertex, and the error blamed its second coordinate.
TEST(MeshFiles, AnOffHeaderWithoutItsEdgeCountIsRead) {
  std::string text = cube_off();
  text.replace(text.find("8 12 0\n"), 7, "8 12\n");
  EXPECT_EQ(validation_error(write_file("two_counts.off", text)), "");
  std::string same_line = cube_off();
  same_line.replace(0, std::string("OFF\n8 12 0\n").size(), "OFF 8 12\n");
  EXPECT_EQ(validation_error(write_file("two_counts_one_line.off", same_line)), "");
}

// A Windows "Unicode" save is UTF-16: named as such rather than read as a NUL after every character.
// PLY and ASCII STL too (an STL's binary layout, whose header is free bytes, is known by its size).
TEST(MeshFiles, AUtf16TextMeshIsNamedAsOne) {
  const std::pair<const char*, std::string> files[] = {
      {"wide.obj", "v 0 0 0\n"},
      {"wide.off", "OFF\n3 1 0\n"},
      {"wide.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"},
      {"wide.stl", "solid part\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid part\n"}};
  for (const auto& [name, text] : files) {
    for (const bool marked : {true, false}) {
      std::string wide = marked ? "\xFF\xFE" : "";
      for (const char c : text) wide += std::string(1, c) + std::string(1, '\0');
      EXPECT_EQ(validation_error(write_file(name, wide)), scratch(name).string() + ": is UTF-16, not UTF-8 text; save it as UTF-8")
          << name << (marked ? " with" : " without") << " a byte-order mark";
    }
  }
}

TEST(MeshFiles, AsciiStlMayStartWithAByteOrderMark) {
  std::string stl = "solid cube\n";
  const Vec3 corners[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (const auto& t : kCubeFaces) {
    stl += "facet normal 0 0 0\nouter loop\n";
    for (const int v : t) stl += "vertex " + std::to_string(corners[v].x) + " " + std::to_string(corners[v].y) + " " + std::to_string(corners[v].z) + "\n";
    stl += "endloop\nendfacet\n";
  }
  stl += "endsolid cube\n";
  EXPECT_EQ(validation_error(write_file("bom.stl", "\xEF\xBB\xBF" + stl)), "");
}

/// Two unit-cube shells in one OFF file, the second scaled by `scale` and moved by `offset`; both
/// outward, or the second wound inward (as a cavity's wall is).
std::string two_cubes_off(double scale, double offset, bool second_inward = false) {
  const double corners[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  std::string text = "OFF\n16 24 0\n";
  for (int shell = 0; shell < 2; ++shell) {
    for (const auto& c : corners) {
      for (const double x : c) text += std::to_string(shell == 0 ? x : offset + scale * x) + " ";
      text += "\n";
    }
  }
  for (int shell = 0; shell < 2; ++shell) {
    for (const auto& t : kCubeFaces) {
      const bool flip = second_inward && shell == 1;
      text += "3 " + std::to_string(t[0] + 8 * shell) + " " + std::to_string(t[flip ? 2 : 1] + 8 * shell) + " " +
              std::to_string(t[flip ? 1 : 2] + 8 * shell) + "\n";
    }
  }
  return text;
}

TEST(MeshFiles, AShellInsideAnotherIsRefusedAndShellsSideBySideAreRead) {
  // One outward shell inside another was read as valid with its volume counted twice, and
  // tetrahedralizing it then lost that volume without a word.
  const std::string nested = validation_error(write_file("nested.off", two_cubes_off(0.2, 0.4)));
  EXPECT_NE(nested.find("nested shells: the component containing face 12 lies inside the component containing face 0"), std::string::npos) << nested;
  // A cavity wound as one should be (inward) was told to turn its faces (audit 32, F14).
  const std::string cavity = validation_error(write_file("cavity.off", two_cubes_off(0.2, 0.4, true)));
  EXPECT_NE(cavity.find("nested shells: the component containing face 12 lies inside the component containing face 0; a solid with a cavity"),
            std::string::npos)
      << cavity;
  EXPECT_NE(validation_error(write_file("inward_apart.off", two_cubes_off(0.5, 2.0, true))).find("inward orientation"), std::string::npos);
  Result<TriangleMesh> apart = read_surface_mesh(write_file("apart.off", two_cubes_off(0.5, 2.0)));
  ASSERT_TRUE(apart) << apart.error();
  Result<SurfaceReport> report = validate_closed_surface(*apart);
  ASSERT_TRUE(report) << report.error();
  EXPECT_EQ(report->components, 2);
  EXPECT_NEAR(report->volume_m3, (1.0 + 0.125) * 1e-9, 1e-21);
}

TEST(MeshFiles, WriteThenReadRoundTripsEveryFormat) {
  Result<TriangleMesh> cube = read_surface_mesh(write_file("rt.off", cube_off()));
  ASSERT_TRUE(cube);
  for (const char* ext : {".off", ".obj", ".ply", ".stl"}) {
    SCOPED_TRACE(ext);
    const auto path = scratch(std::string("roundtrip") + ext);
    ASSERT_TRUE(write_surface_mesh(path, *cube));
    Result<TriangleMesh> back = read_surface_mesh(path);
    ASSERT_TRUE(back) << back.error();
    ASSERT_EQ(back->triangle_count(), 12u);
    Result<SurfaceReport> report = validate_closed_surface(*back);
    ASSERT_TRUE(report) << report.error();
    EXPECT_NEAR(report->volume_m3, 1e-9, 1e-15);
  }
}

}  // namespace

TEST(MeshFiles, CoordinatesBeyondOneKilometreAreRefusedNamingTheVertex) {
  // 1e150 hung the tool's clearance grid, 1e155 and more exhausted memory in the sphere tree, and
  // `mesh check` called them degenerate with an area of inf: every reader now refuses them.
  const std::string faces = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const std::string huge = "OFF\n4 4 0\n0 0 0\n1e150 0 0\n0 10 0\n0 0 10\n" + faces;
  const std::string error = validation_error(write_file("huge.off", huge));
  EXPECT_NE(error.find("huge.off: vertex 1 has coordinate 1e+150 mm, beyond the ±1e+06 mm a surface may reach"), std::string::npos)
      << error;
  const std::string obj = "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 -2e6\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  EXPECT_NE(validation_error(write_file("huge.obj", obj)).find("vertex 3 has coordinate -2e+06 mm"), std::string::npos);
  // At the bound itself the file is fine.
  EXPECT_EQ(validation_error(write_file("km.off", "OFF\n4 4 0\n0 0 0\n1e6 0 0\n0 1e6 0\n0 0 1e6\n" + faces)), "");
  // A mesh built in memory (metres) meets the same bound in validation.
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {2e3, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  Result<SurfaceReport> report = validate_closed_surface(mesh);
  ASSERT_FALSE(report);
  EXPECT_EQ(report.error(), "vertex 1 has coordinate 2e+06 mm, beyond the ±1e+06 mm a surface may reach");
}

TEST(MeshFiles, UnusedVerticesAreCountedAndCanBeDropped) {
  // A vertex no face uses is no part of the surface: a note in the report, never a failure.
  const auto path = write_file("unused.off", "OFF\n5 4 0\n50 50 50\n0 0 0\n10 0 0\n0 10 0\n0 0 10\n"
                                             "3 1 3 2\n3 1 2 4\n3 1 4 3\n3 2 3 4\n");
  Result<TriangleMesh> mesh = read_surface_mesh(path);
  ASSERT_TRUE(mesh) << mesh.error();
  Result<SurfaceReport> report = validate_closed_surface(*mesh);
  ASSERT_TRUE(report) << report.error();
  EXPECT_EQ(report->vertices, 4u);
  EXPECT_EQ(report->unused_vertices, 1u);
  const TriangleMesh compact = without_unused_vertices(*mesh);
  ASSERT_EQ(compact.vertex_count(), 4u);
  EXPECT_EQ(compact.positions[0], mesh->positions[1]);
  EXPECT_EQ(compact.triangles[0], (Triangle{0, 2, 1}));
  EXPECT_EQ(compact.triangles[3], (Triangle{1, 2, 3}));
  // With every vertex used, nothing changes.
  const TriangleMesh again = without_unused_vertices(compact);
  EXPECT_EQ(again.positions, compact.positions);
  EXPECT_EQ(again.triangles, compact.triangles);
}

}  // namespace resecto
