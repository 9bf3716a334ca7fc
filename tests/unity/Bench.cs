// `make bench` figure unity.managed_overhead_ms: what the C# core adds to a SoftDECA frame
// over the native call. Per frame, the time Avatar.EvaluateWeights takes as seen from C#
// (Stopwatch around the call) minus the library's own measurement of that call
// (softdeca_stats.frame_ms, taken inside it); median over the frames of a real take, with the
// managed heap's growth over the loop as a check that frames allocate nothing.
// Usage: mono SoftDeca.Bench.exe BUNDLE AVATAR_DIR TAKE.sdrec OUT.json [FRAMES]
using System;
using System.Collections.Generic;
using System.Diagnostics;
using System.Globalization;
using System.IO;
using SoftDeca;
using SoftDeca.Tests;

internal static class Bench
{
    private static int Main(string[] args)
    {
        if (args.Length < 4)
        {
            Console.Error.WriteLine("usage: SoftDeca.Bench.exe BUNDLE AVATAR_DIR TAKE.sdrec OUT.json [FRAMES]");
            return 2;
        }
        int frames = args.Length > 4 ? int.Parse(args[4], CultureInfo.InvariantCulture) : 300;
        var weights = new List<float[]>();
        using (var player = new Player(args[2]))
        {
            var f = Frame.Create();
            for (int i = 0; i < player.Info.FrameCount && weights.Count < 600; ++i)
            {
                player.GetFrame(i, ref f);
                if (f.Tracking == (int)Tracking.Lost) continue;
                var w = new float[52];
                f.CopyWeights(w);
                for (int s = 0; s < 52; ++s) w[s] = Math.Min(1f, Math.Max(0f, w[s]));
                weights.Add(w);
            }
        }
        Rig rig = Rig.Read(args[1]);
        var overhead = new double[frames];
        var native = new double[frames];
        long heapBefore, heapAfter;
        int gcBefore, gcAfter;
        using (var model = Model.Load(args[0]))
        using (var avatar = new Avatar(model, rig.Neutral.Vertices, rig.Neutral.Triangles, rig.Deltas))
        {
            avatar.Prepare();
            for (int i = 0; i < 50; ++i) avatar.EvaluateWeights(weights[i % weights.Count]);  // warm up
            var clock = new Stopwatch();
            double tick = 1000.0 / Stopwatch.Frequency;
            heapBefore = GC.GetTotalMemory(true);
            gcBefore = GC.CollectionCount(0);
            for (int i = 0; i < frames; ++i)
            {
                float[] w = weights[i % weights.Count];
                clock.Reset();
                clock.Start();
                avatar.EvaluateWeights(w);
                clock.Stop();
                AvatarStats s = avatar.Stats();
                native[i] = s.FrameMs;
                overhead[i] = clock.ElapsedTicks * tick - s.FrameMs;
            }
            heapAfter = GC.GetTotalMemory(false);
            gcAfter = GC.CollectionCount(0);
        }
        Array.Sort(overhead);
        Array.Sort(native);
        double median = overhead[frames / 2], p95 = overhead[(int)(frames * 0.95)];
        string how = "make bench (tests/unity/bench: mono, " + frames + " SoftDECA frames of a real take on the default bundle; " +
                     "C# Stopwatch around Avatar.EvaluateWeights minus softdeca_stats.frame_ms, median)";
        string json = "{\n" +
                      Figure("unity.managed_overhead_ms", median, "ms", how, "0.05") + ",\n" +
                      Figure("unity.managed_overhead_p95_ms", p95, "ms", how.Replace("median", "95th percentile"), "null") + ",\n" +
                      Figure("unity.native_frame_ms", native[frames / 2], "ms", "softdeca_stats.frame_ms of the same frames, median",
                             "null") + ",\n" +
                      Figure("unity.managed_heap_growth_bytes", heapAfter - heapBefore, "bytes",
                             "GC.GetTotalMemory over the timed frames (" + (gcAfter - gcBefore) + " gen-0 collections)", "null") +
                      "\n}\n";
        File.WriteAllText(args[3], json);
        Console.WriteLine("unity.managed_overhead_ms {0:F4} ms (p95 {1:F4}), native frame {2:F3} ms, managed heap growth {3} bytes",
                          median, p95, native[frames / 2], heapAfter - heapBefore);
        return 0;
    }

    private static string Figure(string name, double value, string unit, string how, string target)
    {
        return string.Format(CultureInfo.InvariantCulture,
                             "  \"{0}\": {{\"value\": {1:R}, \"unit\": \"{2}\", \"target\": {3}, \"better\": \"lower\", \"how\": \"{4}\"}}",
                             name, value, unit, target, how);
    }
}
