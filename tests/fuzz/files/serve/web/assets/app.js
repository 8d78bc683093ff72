console.log("thzmap");
