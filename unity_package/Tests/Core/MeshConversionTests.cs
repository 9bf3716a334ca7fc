using System;
using NUnit.Framework;

namespace SoftDeca.Tests
{
    [TestFixture]
    public class MeshConversionTests
    {
        [Test]
        public void UnityPositionsAndWindingRoundTrip()
        {
            var unity = new float[] { 1, 2, 3, -4, 5, 6 };
            var library = new float[6];
            MeshConversion.PositionsToLibrary(unity, library);
            CollectionAssert.AreEqual(new float[] { -1, 2, 3, 4, 5, 6 }, library);
            CollectionAssert.AreEqual(new[] { 0, 2, 1, 3, 5, 4 }, MeshConversion.TrianglesToLibrary(new[] { 0, 1, 2, 3, 4, 5 }));
        }

        [Test]
        public void SplitAndShuffledVerticesFindTheirTemplateVertex()
        {
            var template = new float[] { 0, 0, 0, 0.01f, 0, 0, 0, 0.01f, 0, 0.02f, 0.02f, 0.02f };
            // Unity's order: 3, 0, 1 (split twice, e.g. at a UV seam), 2.
            var mesh = new float[] { 0.02f, 0.02f, 0.02f, 0, 0, 0, 0.01f, 0, 0, 0.01f, 0, 0.000001f, 0, 0.01f, 0 };
            CollectionAssert.AreEqual(new[] { 3, 0, 1, 1, 2 }, TemplateMapping.Build(mesh, template));
            var off = new float[] { 0.5f, 0, 0 };
            var e = Assert.Throws<ArgumentException>(() => TemplateMapping.Build(off, template));
            StringAssert.Contains("template topology", e.Message);
        }

        [Test]
        public void RegionsPaintTheFacesWhoseCentroidIsInside()
        {
            var neutral = new float[] { 0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 0, 6, 5, 0, 5, 6, 0 };
            var tris = new[] { 0, 1, 2, 3, 4, 5 };
            var faces = new float[] { 1, 1 };
            Assert.AreEqual(1, RegionMap.Paint(neutral, tris, faces, 0.3f, 0.3f, 0, 0.2f, 7));
            CollectionAssert.AreEqual(new float[] { 7, 1 }, faces);
            Assert.Throws<ArgumentException>(() => RegionMap.Paint(neutral, tris, new float[3], 0, 0, 0, 1, 1));
        }

        [Test]
        public void TimecodesCountFramesAtTheTakesRate()
        {
            Assert.AreEqual("01:02:03:30", Timecode.Format(3723.5, 60));
            Assert.AreEqual("00:00:00:00", Timecode.Format(0, 30));
            Assert.Throws<ArgumentOutOfRangeException>(() => Timecode.Format(1, 0));
        }
    }
}
