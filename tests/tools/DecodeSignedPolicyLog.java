// Reads an LCM log holding MASA_POLICY messages signed with a run key and decodes each one as
// lcm-spy does (the class lcm-gen made, built from a DataInput over the whole message), printing
// its fields and the bytes the decoder left after the last field: the run key's trailer.
//   java -cp lcm.jar:masa_lcmtypes.jar:. DecodeSignedPolicyLog LOG
import java.io.EOFException;
import java.io.IOException;
import java.nio.charset.StandardCharsets;

import lcm.lcm.LCMDataInputStream;
import lcm.logging.Log;

public class DecodeSignedPolicyLog {
  public static void main(String[] args) throws IOException {
    Log log = new Log(args[0], "r");
    int decoded = 0;
    while (true) {
      Log.Event event;
      try {
        event = log.readNext();
      } catch (EOFException end) {
        break;
      }
      if (!event.channel.equals("MASA_POLICY")) continue;
      LCMDataInputStream in = new LCMDataInputStream(event.data);
      masa.lcmt_policy_params m = new masa.lcmt_policy_params(in);
      byte[] rest = new byte[in.available()];
      in.readFully(rest);
      String marker = rest.length >= 4 ? new String(rest, 0, 4, StandardCharsets.US_ASCII) : "";
      System.out.printf("MASA_POLICY run_id %d version %d task %s method %s num_params %d params %d obs_dim %d "
                        + "obs_std %d; %d bytes after the last field, marker %s%n",
                        m.run_id, m.version, m.task, m.method, m.num_params, m.params.length, m.obs_dim,
                        m.obs_std.length, rest.length, marker);
      ++decoded;
    }
    System.out.println("decoded " + decoded + " MASA_POLICY messages");
  }
}
