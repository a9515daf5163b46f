// Values entering through OBJ and MTL files (src/scene/obj_check.cpp): tinyobjloader read NaN and
// Inf coordinates as 0, let 1e39 overflow its floats, and took absurd indices with a warning;
// each is now an error naming the file and line. Also: forward references still load, files that
// are not regular files are refused, huge polygons are refused before the triangulator's cubic
// time, a transform that takes a vertex beyond float range is an error.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <string>

#include "lucent/error.hpp"
#include "scene/loaders.hpp"
#include "support.hpp"

namespace test_obj_validation {

namespace {

using lucent::Scene;

/// Loads `text` as an OBJ (and `mtl` as m.mtl beside it); returns the error, "" when it loads.
std::string obj_error(const std::string& text, const std::string& mtl = "",
                      const glm::dmat4& xf = glm::dmat4(1.0), Scene* out = nullptr) {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/m.obj", text);
  if (!mtl.empty()) lucent::test::write_file(dir + "/m.mtl", mtl);
  Scene scene;
  try {
    lucent::scene_detail::load_obj(scene, dir + "/m.obj", xf, -1);
  } catch (const lucent::Error& e) {
    std::string m = e.what();
    auto at = m.find("m.obj");
    return at == std::string::npos ? m : m.substr(at);
  }
  if (out) *out = scene;
  return "";
}

const std::string kTri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

TEST(ObjValidation, NonFiniteAndHugeCoordinatesAreErrors) {
  EXPECT_EQ(obj_error("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            "m.obj:1: vertex line: 'nan' is not a finite number");
  EXPECT_EQ(obj_error(kTri + "v 0 -inf 0\nf 1 2 3\n"),
            "m.obj:4: vertex line: '-inf' is not a finite number");
  EXPECT_EQ(obj_error(kTri + "vn 0 Infinity 0\nf 1 2 3\n"),
            "m.obj:4: normal line: 'Infinity' is not a finite number");
  EXPECT_EQ(obj_error(kTri + "vt NAN 0\nf 1 2 3\n"),
            "m.obj:4: texture coordinate line: 'NAN' is not a finite number");
  EXPECT_EQ(obj_error(kTri + "v 1e39 0 0\nf 1 2 3\n"),
            "m.obj:4: vertex line: '1e39' is out of range for a float");
  EXPECT_EQ(obj_error(kTri + "v 1e999 0 0\nf 1 2 3\n"),
            "m.obj:4: vertex line: '1e999' is out of range");
  // underflow is zero, not an error
  Scene s;
  ASSERT_EQ(obj_error("v 1e-999 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "", glm::dmat4(1.0), &s), "");
  EXPECT_EQ(s.positions[0].x, 0.0);
}

// tinyobjloader reads a number's exponent into an int, overflowing on ten digits (undefined
// behaviour, found by fuzz_obj on a tag line): every number it parses is checked first.
TEST(ObjValidation, ExponentsOfTenDigitsAreErrors) {
  EXPECT_EQ(obj_error(kTri + "v 1e-2147483648 0 0\nf 1 2 3\n"),
            "m.obj:4: '1e-2147483648': the exponent is out of range");
  EXPECT_EQ(obj_error(kTri + "t crease 0/1/0 2.5e+002147483649\nf 1 2 3\n"),
            "m.obj:4: '2.5e+002147483649': the exponent is out of range");
  const std::string obj = "mtllib m.mtl\n" + kTri + "usemtl a\nf 1 2 3\n";
  EXPECT_NE(obj_error(obj, "newmtl a\nmap_Kd -bm 1E-99999999999 t.png\n")
                .find("m.mtl:2: '1E-99999999999': the exponent is out of range"),
            std::string::npos);
  // tinyobjloader reads on past a '#' inside a line: so do the checks
  EXPECT_EQ(obj_error(kTri + "vw 1 0 # 1e39\nf 1 2 3\n"),
            "m.obj:4: skin weight line: '#' is not a number");
  EXPECT_EQ(obj_error(kTri + "v 1 2 3 # 1e-2147483648\nf 1 2 3\n"),
            "m.obj:4: '1e-2147483648': the exponent is out of range");
  // nine digits are parsed (as 0 here); names are not numbers
  EXPECT_EQ(obj_error("v 1e-999999999 0 0\nv 1 0 0\nv 0 1 0\nt a 0/0/1 e1234567890\nf 1 2 3\n"),
            "");
}

// tinyobjloader computes (digits before the point) x 5^e x 2^e: 5^e overflows above e = 441 and
// the digits overflow past 308 of them, so numbers whose value is a fine float came out as NaN
// or infinity ("vt 0 0e761" is 0 x inf; found by fuzz_obj). Such numbers are refused; the ones
// next to the bounds load, and tinyobjloader reads them as finite numbers.
TEST(ObjValidation, NumbersTinyobjloaderReadsAsNanOrInfinityAreErrors) {
  EXPECT_EQ(obj_error(kTri + "vt 0 0e761\nf 1 2 3\n"),
            "m.obj:4: texture coordinate line: '0e761' has an exponent above 300 (tinyobjloader "
            "cannot read it)");
  // 10, written with its digit 331 places behind the point: tinyobjloader's mantissa underflows
  // to 0, so it read 0
  const std::string ten = "0." + std::string(330, '0') + "1e332";
  EXPECT_NE(obj_error(kTri + "v " + ten + " 0 0\nf 1 2 3\n").find("m.obj:4: vertex line: '0.000"),
            std::string::npos);
  EXPECT_NE(obj_error(kTri + "v " + ten + " 0 0\nf 1 2 3\n").find("has an exponent above 300"),
            std::string::npos);
  // 1e9 and 1e-491 written with 310 digits before the point (tinyobjloader's mantissa overflows:
  // infinity, and inf x 5^-800 = inf x 0 = NaN); the second also underflows a double, a branch of
  // its own in the checks
  const std::string big = "1" + std::string(309, '0');
  EXPECT_NE(
      obj_error(kTri + "vn 0 " + big + "e-300 0\nf 1 2 3\n").find("m.obj:4: normal line: '1000"),
      std::string::npos);
  EXPECT_NE(obj_error(kTri + "v " + big + "e-800 0 0\nf 1 2 3\n")
                .find("has more than 308 digits before the point (tinyobjloader cannot read it)"),
            std::string::npos);
  // MTL numbers go through the same checks
  const std::string obj = "mtllib m.mtl\n" + kTri + "usemtl a\nf 1 2 3\n";
  EXPECT_NE(obj_error(obj, "newmtl a\nKd 0.5 0E+500 0.5\n")
                .find("m.mtl:2: Kd line: '0E+500' has an exponent above 300"),
            std::string::npos);
  // at the bounds: an exponent of 300, 308 digits before the point, any negative exponent
  Scene s;
  const std::string too_large = "0." + std::string(199, '0') + "1e300";  // 1e100
  EXPECT_NE(obj_error(kTri + "v " + too_large + " 0 0\nf 1 2 3\n").find("out of range for a float"),
            std::string::npos);
  const std::string ok_x = "0." + std::string(298, '0') + "5e300";  // 50
  const std::string ok_y = std::string(308, '9') + "e-308";         // 1
  ASSERT_EQ(obj_error("v " + ok_x + " " + ok_y + " 0e300\nv 1 0 0\nv 0 1 1e-999999999\n" +
                          "vt 0 0e-761\nf 1/1 2/1 3/1\n",
                      "", glm::dmat4(1.0), &s),
            "");
  EXPECT_NEAR(s.positions[0].x, 50.0, 1e-4);
  EXPECT_NEAR(s.positions[0].y, 1.0, 1e-6);
  EXPECT_EQ(s.positions[0].z, 0.0);
  EXPECT_EQ(s.positions[2].z, 0.0);
  ASSERT_EQ(s.uvs.size(), 1u);
  EXPECT_EQ(s.uvs[0].y, 0.0);
}

TEST(ObjValidation, AbsurdIndicesAreErrors) {
  EXPECT_EQ(obj_error(kTri + "f 1 2 99999999999999999999999\n"),
            "m.obj:4: face: vertex index 99999999999999999999999 is out of range");
  EXPECT_EQ(obj_error(kTri + "f 1 2 2147483648\n"),
            "m.obj:4: vertex index 2147483648 is out of range (the file defines 3)");
  EXPECT_EQ(obj_error(kTri + "f 1 2 -2147483649\n"),
            "m.obj:4: face: vertex index -2147483649 is out of range (3 defined so far)");
  EXPECT_EQ(obj_error(kTri + "f 1 2 0\n"),
            "m.obj:4: face: vertex index 0 (OBJ indices start at 1)");
  EXPECT_EQ(obj_error(kTri + "f 1/1 2/1 3/1\n"),
            "m.obj:4: texture coordinate index 1 is out of range (the file defines 0)");
  EXPECT_EQ(obj_error(kTri + "f 1//-1 2//-1 3//-1\n"),
            "m.obj:4: face: normal index -1 is out of range (0 defined so far)");
  EXPECT_EQ(obj_error(kTri + "f 1/2/3/4 2 3\n"),
            "m.obj:4: face: '1/2/3/4' has more than 3 indices");
  EXPECT_EQ(obj_error(kTri + "l 1 7\n"),
            "m.obj:4: vertex index 7 is out of range (the file defines 3)");
  EXPECT_EQ(obj_error(kTri + "p 1.5\n"),
            "m.obj:4: point element: vertex index '1.5' is not an integer");
  // a face may name vertices defined further down (tinyobjloader accepts it): still loads
  Scene s;
  EXPECT_EQ(obj_error("v 0 0 0\nf 1 2 3\nv 1 0 0\nv 0 1 0\n", "", glm::dmat4(1.0), &s), "");
  EXPECT_EQ(s.triangles.size(), 1u);
}

// A PLY, STL or glTF file named as a mesh (the Stanford bunny comes as PLY) loaded as an OBJ of no
// faces: a warning, and an image without the mesh. A file that defines no vertex or face and has a
// statement OBJ does not have is refused, naming its first such line; one of comments alone, or
// an OBJ with statements lucent ignores, still loads.
TEST(ObjValidation, FilesOfAnotherFormatAreRefused) {
  const std::string not_obj =
      "' is no OBJ statement, and the file defines no vertex or face: not a Wavefront OBJ file "
      "(lucent reads meshes as OBJ)";
  EXPECT_EQ(obj_error("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n"
                      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
            "m.obj:1: 'ply" + not_obj);
  EXPECT_EQ(obj_error("solid s\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n"
                      "   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid s\n"),
            "m.obj:1: 'solid" + not_obj);
  EXPECT_EQ(obj_error("# a comment\n\n{\"asset\": {\"version\": \"2.0\"}}\n"),
            "m.obj:3: '{\"asset\":" + not_obj);
  EXPECT_EQ(obj_error("# nothing but a comment\n"), "");
  // a line continued on the next (the OBJ specification's '\'), which tinyobjloader does not read
  EXPECT_EQ(obj_error("v 0 0 \\\n  0\n"),
            "m.obj:1: a '\\' at the end of a line continues it on the next, which lucent does "
            "not read: join the two lines");
  EXPECT_EQ(obj_error(kTri + "f 1 2 \\ \r\n3\n"),
            "m.obj:4: a '\\' at the end of a line continues it on the next, which lucent does "
            "not read: join the two lines");
  EXPECT_EQ(obj_error(kTri + "f 1 2 3 # a comment \\\n"), "");
  EXPECT_EQ(obj_error("g name\\\n" + kTri + "f 1 2 3\n"), "");  // a name, as tinyobjloader reads it
  EXPECT_EQ(obj_error("g group\n"), "");
  Scene s;
  EXPECT_EQ(obj_error("vertex 0 0 0\n" + kTri + "f 1 2 3\n", "", glm::dmat4(1.0), &s), "");
  EXPECT_EQ(s.triangles.size(), 1u);
}

// "f 1/ 2/ 3/ 4/1" passed the check (an empty texture coordinate taken as none), but
// tinyobjloader's atoi skipped the space after "1/" and read the next corner's vertex index as its
// texture coordinate: the quad loaded with UVs 2, 3, 4 and 1 without a word, and "f 1/ 2/ 3/ 4"
// (vt 4 of 3) was refused as "a face index is out of range" naming no line. Found by loading
// faces with trailing slashes. A corner ending with a slash is now an error naming its line.
TEST(ObjValidation, CornersEndingWithASlashAreErrors) {
  const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
  EXPECT_EQ(obj_error(quad + "f 1/ 2/ 3/ 4/1\n"),
            "m.obj:9: face: '1/' ends with a slash (the forms are v, v/vt, v//vn and v/vt/vn)");
  EXPECT_EQ(obj_error(quad + "f 1/1 2/2 3/ 4\n"),
            "m.obj:9: face: '3/' ends with a slash (the forms are v, v/vt, v//vn and v/vt/vn)");
  EXPECT_EQ(obj_error(quad + "vn 0 0 1\nf 1/1/ 2/2/1 3/3/1\n"),
            "m.obj:10: face: '1/1/' ends with a slash (the forms are v, v/vt, v//vn and v/vt/vn)");
  EXPECT_EQ(obj_error(quad + "f 1// 2 3\n"),
            "m.obj:9: face: '1//' ends with a slash (the forms are v, v/vt, v//vn and v/vt/vn)");
  // the four forms, mixed in one face, still load
  Scene s;
  ASSERT_EQ(obj_error(quad + "vn 0 0 1\nf 1 2/2 3//1 4/4/1\n", "", glm::dmat4(1.0), &s), "");
  EXPECT_EQ(s.triangles.size(), 2u);
}

// A comment at the end of a face ("f 1 2 3 # top") passed the text check, which stops at a
// '#', but tinyobjloader reads every word of an f, l or p line as an index: the file was refused
// as "m.obj:4: malformed face: an index is 0 or not a number", though docs/obj-mtl.md lists
// comments among what has no effect. Found by loading faces with trailing comments. Such
// comments are now blanked before tinyobjloader reads the file.
TEST(ObjValidation, CommentsAtTheEndOfElementsAreIgnored) {
  Scene s;
  ASSERT_EQ(obj_error(kTri + "v 1 1 0\nf 1 2 3 # first\nf 2 4 3\t#second, 9 9 9\n"
                             "l 1 2 # an edge\np 1 #a point\n",
                      "", glm::dmat4(1.0), &s),
            "");
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(s.triangles[1].v[0], 1);
  EXPECT_EQ(s.triangles[1].v[1], 3);
  EXPECT_EQ(s.triangles[1].v[2], 2);
  // the lines are kept: a later error names its own line; a '#' inside a word is no comment
  EXPECT_EQ(obj_error(kTri + "f 1 2 3 # c\nf 1 2 4\n"),
            "m.obj:5: vertex index 4 is out of range (the file defines 3)");
  EXPECT_EQ(obj_error(kTri + "f 1 2 3#c\n"), "m.obj:4: face: vertex index '3#c' is not an integer");
}

TEST(ObjValidation, HugePolygonsAreRefusedQuickly) {
  std::string text;
  for (int i = 0; i < 1100; ++i)
    text += "v " + std::to_string(i % 7) + " " + std::to_string(i % 3) + " 0\n";
  std::string face = "f";
  for (int i = 1; i <= 1100; ++i) face += " " + std::to_string(i);
  auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(obj_error(text + face + "\n"),
            "m.obj:1101: face has 1100 corners, more than the 255 tinyobjloader can hold");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0);
}

// tinyobjloader keeps a face's corner count in an unsigned char: a polygon of 256 to 1024
// corners passed the check (then 1024 corners) and came back from tinyobjloader with its count
// wrapped, refused as "m.obj: inconsistent face list" (300 corners) or "m.obj: a face has 0
// corners" (256), naming no line. Found by loading a 300-corner star polygon. A polygon of 255
// corners, the most tinyobjloader holds, still loads, its area whole.
TEST(ObjValidation, PolygonsBeyondTinyobjloadersCornerCountAreRefusedWithTheirLine) {
  auto polygon = [](int n) {
    std::string text;
    for (int i = 0; i < n; ++i) {
      const double a = 2 * 3.14159265358979 * i / n, r = i % 2 ? 1.0 : 0.5;  // a star
      text +=
          "v " + std::to_string(r * std::cos(a)) + " " + std::to_string(r * std::sin(a)) + " 0\n";
    }
    text += "f";
    for (int i = 1; i <= n; ++i) text += " " + std::to_string(i);
    return text + "\n";
  };
  EXPECT_EQ(obj_error(kTri + "f 1 2 3\n" + polygon(300)),
            "m.obj:305: face has 300 corners, more than the 255 tinyobjloader can hold");
  EXPECT_EQ(obj_error(polygon(256)),
            "m.obj:257: face has 256 corners, more than the 255 tinyobjloader can hold");
  Scene s;
  ASSERT_EQ(obj_error(polygon(255), "", glm::dmat4(1.0), &s), "");
  EXPECT_EQ(s.triangles.size(), 253u);
}

TEST(ObjValidation, MtlNumbersAreChecked) {
  const std::string obj = "mtllib m.mtl\n" + kTri + "usemtl a\nf 1 2 3\n";
  struct Case {
    std::string line, error;
  } cases[] = {
      {"Kd nan 0.5 0.5", "m.mtl:2: Kd line: 'nan' is not a finite number"},
      {"Ks 1 1e39 1", "m.mtl:2: Ks line: '1e39' is out of range for a float"},
      {"Ke -1 0 0", "m.mtl:2: Ke line: '-1' is negative"},
      {"Kd 0.5 0.5", "m.mtl:2: Kd line has 2 numbers, needs 3 (or 1, for grey)"},
      {"Ks 1 1 1 1", "m.mtl:2: Ks line has 4 numbers, needs 3 (or 1, for grey)"},
      {"Ns inf", "m.mtl:2: Ns line: 'inf' is not a finite number"},
      {"Ni", "m.mtl:2: Ni line has no number"},
      {"illum 99", "m.mtl:2: illum line: '99' is not an illumination model (0 to 10)"},
      {"Kd xyz 0.5 0.5", "m.mtl:2: Kd xyz line has 2 numbers, needs 1 or 3"},
      {"Ke xyz 2e38 0 0", "m.mtl:2: Ke xyz line: the colour is out of range for a float in sRGB"},
      {"Ks xyz 0.5 -1 0.5", "m.mtl:2: Ks line: '-1' is negative"},
      {"Kd xyz nan", "m.mtl:2: Kd line: 'nan' is not a finite number"},
      {"Kd spectral", "m.mtl:2: Kd spectral line has no file name"},
      {"Ke spectral x.rfl inf", "m.mtl:2: Ke line: 'inf' is not a finite number"},
  };
  for (const Case& c : cases) {
    std::string err = obj_error(obj, "newmtl a\n" + c.line + "\n");
    EXPECT_NE(err.find(c.error), std::string::npos) << c.line << ": " << err;
    EXPECT_EQ(err.find('\n'), std::string::npos) << err;
  }
  // a value the scene refuses is named by the MTL file, the material's line and its statement:
  // the error came at render time as "s.json: /materials/m.obj:a/ior: ...", a place of no file
  const std::string glass = obj_error(obj, "# glass\nnewmtl a\nillum 7\nNi 1000\n");
  EXPECT_NE(glass.find("/m.mtl:2: material 'a': ior (Ni): must be in [0.05, 20], got 1000"),
            std::string::npos)
      << glass;
  // the spectral and xyz forms (read_colour_forms); valid libraries load
  EXPECT_EQ(obj_error(obj, "newmtl a\nKd spectral x.rfl\nKd 0.5 0.5 0.5\nNs 10\nillum 2\n"), "");
  EXPECT_EQ(obj_error(obj, "newmtl a\nKd xyz 0.5\nKs xyz 0.1 0.2 0.1\nKe spectral x.rfl 2\n"), "");
}

TEST(ObjValidation, TransformBeyondFloatRangeIsAnError) {
  glm::dmat4 xf = glm::scale(glm::dmat4(1.0), glm::dvec3(1e30));
  EXPECT_EQ(obj_error("v 0 0 0\nv 1e9 0 0\nv 0 1 0\nf 1 2 3\n", "", xf),
            "m.obj:2: vertex 2 (1e+39, 0, 0) after the transform is beyond lucent's geometry range "
            "(coordinates of magnitude at most 1e+12, where the kernel's float intersection "
            "arithmetic still holds)");
  EXPECT_EQ(obj_error("v 0 0 0\nv 0 0 0\nv 0 2e12 0\nf 1 2 3\n"),
            "m.obj:3: vertex 3 (0, 2e+12, 0) is beyond lucent's geometry range (coordinates of "
            "magnitude at most 1e+12, where the kernel's float intersection arithmetic still "
            "holds)");
}

TEST(ObjValidation, FilesThatAreNotRegularAreRefused) {
  std::string dir = lucent::test::temp_dir();
  Scene scene;
  for (const std::string& path : {std::string("/dev/zero"), dir}) {
    try {
      lucent::scene_detail::load_obj(scene, path, glm::dmat4(1.0), -1);
      ADD_FAILURE() << path;
    } catch (const lucent::Error& e) {
      EXPECT_EQ(std::string(e.what()), path == dir
                                           ? dir + ": is a directory, not an OBJ file"
                                           : "/dev/zero: is a device, not an OBJ file (only "
                                             "regular files are read)");
    }
  }
  // a NUL byte: a binary file, not an OBJ
  EXPECT_EQ(obj_error(kTri + std::string("f 1 2 3\0\n", 8)),
            "m.obj: byte 32 is a NUL byte: not a text OBJ file");
  // an MTL library that is a directory or a device: a warning, the default material
  lucent::test::CaptureWarnings warnings;
  std::string d2 = lucent::test::temp_dir();
  std::filesystem::create_directories(d2 + "/m.mtl");
  lucent::test::write_file(d2 + "/m.obj", "mtllib m.mtl\nmtllib /dev/zero\n" + kTri + "f 1 2 3\n");
  lucent::scene_detail::load_obj(scene, d2 + "/m.obj", glm::dmat4(1.0), -1);
  EXPECT_EQ(
      warnings.count("m.mtl: is a directory, not an MTL file; faces use the default material"), 1)
      << warnings.dump();
  EXPECT_EQ(warnings.count("/dev/zero: is a device, not an MTL file"), 1) << warnings.dump();
}

}  // namespace

}  // namespace test_obj_validation
