
    $readmemh("map2_x.hex", map2, 0, MAP_ENTRIES - 1);
    $readmemh("map2_y.hex", map2, MAP_ENTRIES, 2 * MAP_ENTRIES - 1);
    $readmemh("map2_z.hex", map2, 2 * MAP_ENTRIES, 3 * MAP_ENTRIES - 1);
    for (k = 0; k < NWRITES; k = k + 1) begin
      wi = k[A+1:0];
      if (^map2[wi] === 1'bx) $fatal(1, "map2_*.hex: entry %0d is missing or not hex", k);
    end
    nwr = 0;
