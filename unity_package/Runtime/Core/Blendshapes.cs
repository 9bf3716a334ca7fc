using System;
using System.Collections.Generic;

namespace SoftDeca
{
    /// <summary>
    /// The library's canonical blendshape order and a name-based map from any source's order
    /// (AR Foundation's ARKitBlendShapeLocation, Live Link Face, a rig) into it. Sources never
    /// match by position: each source name is matched to a canonical name by the library's rule
    /// for rigs' names (CanonicalIndex: "EyeBlinkLeft", "eyeBlink_L" and
    /// "blendShape1.eyeBlinkLeft" are the same shape).
    /// </summary>
    public sealed class BlendshapeMap
    {
        public const int Count = 52;
        private static string[] canonical;

        private readonly int[] toCanonical;
        private readonly string[] unmatched;

        /// <summary>The canonical names as the library reports them ("browDownLeft" = 0 ... "tongueOut" = 51).</summary>
        public static string[] CanonicalNames
        {
            get
            {
                if (canonical == null)
                {
                    Library.EnsureCompatible();
                    var names = new string[Count];
                    for (uint i = 0; i < Count; ++i) names[i] = Utf8.FromNative(NativeMethods.softdeca_blendshape_get_name(i));
                    canonical = names;
                }
                return (string[])canonical.Clone();
            }
        }

        /// <summary>
        /// The canonical index of the ARKit shape a name denotes, or -1: ARKit's names in any case,
        /// behind a prefix or namespace ("blendShape1.eyeBlinkLeft", "AK_07_EyeBlinkLeft"), with
        /// the side as a suffix ("eyeBlink_L", "eyeBlink.R"). The library's rule
        /// (softdeca_blendshape_find_index), the same for every part of the product.
        /// </summary>
        public static unsafe int CanonicalIndex(string name)
        {
            if (name == null) throw new ArgumentNullException("name");
            Library.EnsureCompatible();
            byte[] text = Utf8.ToNative(name, "name");
            int index;
            Status s;
            fixed (byte* p = text) s = NativeMethods.softdeca_blendshape_find_index(p, out index);
            Library.Check(s);
            return index;
        }

        /// <summary>
        /// A map from source slots to canonical indices. sourceNames[k] names the source's slot k
        /// (e.g. the ARKitBlendShapeLocation member whose value is k); null or unknown names are
        /// ignored and listed in Unmatched.
        /// </summary>
        public BlendshapeMap(IList<string> sourceNames)
        {
            if (sourceNames == null) throw new ArgumentNullException("sourceNames");
            toCanonical = new int[sourceNames.Count];
            var missing = new List<string>();
            var seen = new bool[Count];
            for (int k = 0; k < sourceNames.Count; ++k)
            {
                int c = sourceNames[k] == null ? -1 : CanonicalIndex(sourceNames[k]);
                if (c >= 0 && seen[c])
                    throw new ArgumentException("two source slots name the blendshape '" + sourceNames[k] + "'", "sourceNames");
                if (c >= 0) seen[c] = true;
                else if (sourceNames[k] != null) missing.Add(sourceNames[k]);
                toCanonical[k] = c;
            }
            unmatched = missing.ToArray();
        }

        /// <summary>Source names that are not ARKit blendshapes (ignored when applying).</summary>
        public string[] Unmatched { get { return (string[])unmatched.Clone(); } }

        public int SourceCount { get { return toCanonical.Length; } }

        /// <summary>The canonical index of source slot k, or -1 when it is not an ARKit blendshape.</summary>
        public int ToCanonical(int sourceSlot) { return toCanonical[sourceSlot]; }

        /// <summary>
        /// Writes one source coefficient into canonical weights (clamped to [0, 1]); false when the
        /// slot is not an ARKit blendshape. For sources that report (slot, value) pairs.
        /// </summary>
        public bool Set(float[] canonicalWeights, int sourceSlot, float value)
        {
            if ((uint)sourceSlot >= (uint)toCanonical.Length) return false;
            int c = toCanonical[sourceSlot];
            if (c < 0) return false;
            canonicalWeights[c] = value < 0 ? 0 : value > 1 ? 1 : (value >= 0 ? value : 0);
            return true;
        }

        /// <summary>All source coefficients (SourceCount values, source order) into canonical weights.</summary>
        public void Apply(float[] sourceValues, float[] canonicalWeights)
        {
            if (sourceValues == null) throw new ArgumentNullException("sourceValues");
            if (canonicalWeights == null || canonicalWeights.Length < Count)
                throw new ArgumentException("canonicalWeights needs 52 floats", "canonicalWeights");
            if (sourceValues.Length < toCanonical.Length)
                throw new ArgumentException("sourceValues has " + sourceValues.Length + " values, the map " + toCanonical.Length,
                                            "sourceValues");
            for (int k = 0; k < toCanonical.Length; ++k) Set(canonicalWeights, k, sourceValues[k]);
        }
    }
}
